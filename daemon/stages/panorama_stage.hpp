#pragma once
// The panorama: every set's camera frames gathered through the panorama LUT (processing/
// stitcher.hpp), colour-corrected (Poisson or gain compensation, as colour_correction says) and
// each faulty camera's part marked. Made for every set, shown or not: colour correction follows
// the pictures over time.
//
// Mounts corrected from the road (the calibration watch, calibration_watch.correct: apply) come in
// through remount(): the tables for them (panorama_tables.hpp) are built on a thread of their own
// beside the sets and taken into use at the start of the first set after they are made; what
// others built from the tables before (a view's table, the GPU's stitch, the watch's probes)
// they build again when generation() changes.

#include <array>
#include <chrono>
#include <cstdint>
#include <future>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

#include "common/dmabuf_planes.hpp"
#include "common/work_pool.hpp"
#include "daemon/config/config.hpp"
#include "daemon/pipeline_stage.hpp"
#include "daemon/stages/panorama_tables.hpp"
#include "processing/colour/poisson_correction.hpp"
#include "processing/stitch/panorama_lut.hpp"
#include "processing/stitch/panorama_ownership.hpp"
#include "processing/stitch/stitcher.hpp"

namespace surroundd::daemon {

class PanoramaStage final : public PipelineStage {
 public:
  // Builds the LUT (or reads it from the cache) and the colour correction on `pool`, which must
  // outlive the stage. Throws std::runtime_error naming the config for a rig that cannot make a
  // panorama.
  PanoramaStage(const Config& config, WorkPool& pool);
  ~PanoramaStage() override;

  // Takes remounted tables into use where they are made. Stitches the panorama where a later stage
  // needs it this set (Need::kPanorama: an output of it, a view drawn from it), and hands it on in
  // FrameWork::panorama; else only updates the colour correction (it follows the pictures over
  // time; views gathered through their own LUTs apply it).
  void process(FrameWork& work, StageTimes& times) override;
  // The Poisson correction's seams and balance gains as the last set left them.
  void report(PipelineReport& report) const override;

  // The corrected panorama of the last set that needed it, reused for every set; of lut().size.
  const cv::Mat& picture() const { return panorama_; }
  std::optional<StreamPicture> streamPicture(OutputStream stream) const override {
    if (stream != OutputStream::kPanorama) return std::nullopt;
    return StreamPicture{&panorama_, tables_->lut.size};
  }
  const processing::PanoramaLut& lut() const { return tables_->lut; }
  // The rig the LUT was built for (body masks included).
  const processing::Rig& rig() const { return tables_->rig; }
  WorkPool& pool() const { return pool_; }
  // The frames of the set process() was last given, as the stitch samples them (a missing
  // camera's black), all held in frameFormat(): for a stitch elsewhere (the GPU's). Views into the
  // set's frames, to be read only while that set is processed: a frame lent a driver's buffer
  // gives it back when the set ends.
  const std::vector<cv::Mat>& frames() const { return stitched_; }
  // Where each of those frames lies in its driver's DMABUFs, where it was lent one (planes 0
  // where not): for a GPU to import it instead.
  const std::vector<DmabufPlanes>& dmabufs() const { return dmabufs_; }
  PixelFormat frameFormat() const { return format_; }
  // The Poisson correction's field, updated by each process(), for a stitcher to apply; none with
  // another method or none.
  std::optional<processing::ColourField> colourField() const {
    const auto& poisson = tables_->poisson;
    return poisson ? std::optional(poisson->asColourField()) : std::nullopt;
  }

  // The panorama made through `rig`'s mounts from the first set after its tables are made (on a
  // thread of their own; a build that fails is logged, and the mounts stay as they were). A
  // remount while one is being built takes its place. `rig`'s cameras are the stage's, body masks
  // included.
  void remount(processing::Rig rig);
  // Whether a remount was asked for and is not yet in use (being built, or made and waiting for
  // the next set); false again once taken, or once its build failed.
  bool remounting() const { return remount_.valid(); }
  // Changes each time remounted tables are taken into use: rig(), lut() and the colour field are
  // new, and what was built from the old ones is to be built again.
  std::uint64_t generation() const { return generation_; }

  // A view that does not move, made the way the panorama is made but through the view's own LUT
  // (processing/stitch/view_lut.hpp): gathered from the set's frames straight into the view's
  // picture, colour-corrected and each faulty camera's part marked. Built by buildView().
  class ViewPicture {
   public:
    // From where each of the view's pixels samples the panorama (SurroundView::
    // panoramaPositions()) made through `tables`, composed on `compose`; it gathers on `pool`.
    ViewPicture(const PanoramaTables& tables, const cv::Mat& panoramaPositions, WorkPool& compose,
                WorkPool& pool);
    cv::Size size() const { return lut_.size; }
    // How long its composition took.
    std::chrono::duration<double> composedIn() const { return composedIn_; }

   private:
    friend class PanoramaStage;
    processing::PanoramaLut lut_;
    processing::Stitcher stitcher_;  // borrows lut_
    processing::PanoramaOwnership ownership_;
    processing::PoissonColourCorrection::ViewSamples fieldSamples_;  // colour_correction: poisson
    std::chrono::duration<double> composedIn_{0};
    std::uint64_t generation_ = 0;  // of the tables it was made from
  };
  // Builds a view's picture on a thread of its own, from the LUT and the colour correction's
  // set-up only (process() may run meanwhile): composing it takes tenths of a second, which no
  // set should wait for. The stage waits for the builds under way when it goes.
  std::future<std::unique_ptr<ViewPicture>> buildView(cv::Mat panoramaPositions);
  // The view's picture of the set process() was last given, in two steps, so that what is laid
  // where the view shows no panorama (the car, the background) goes in between, where correcting
  // leaves it as it is: gathered into `picture`, 8-bit BGR of its size; then corrected by the
  // fields or gains the last update() fitted and each faulty camera's part marked. With `i420`,
  // the picture is also converted into it (processing/stitch/i420_picture.hpp) for an encoder:
  // in the same pass as the Poisson field where no camera is faulty. A view made before the
  // last remount cannot be corrected (std::logic_error): it is to be built again.
  void gather(ViewPicture& view, cv::Mat& picture);
  void correct(ViewPicture& view, const FrameWork& work, cv::Mat& picture, cv::Mat* i420);

 private:
  void takeRemountedTables();
  // Fills stitched_ and corrected_ with the set's frames; returns the format they are held in.
  PixelFormat gatherFrames(FrameWork& work);
  // A missing camera's stand-in, made the first time a camera of that format is missing.
  const cv::Mat& blackFrame(std::size_t camera, PixelFormat format);

  const Config config_;  // what remounted tables are built for
  WorkPool& pool_;
  // Shared with the view builds made from them, which may outlive their use here.
  std::shared_ptr<PanoramaTables> tables_;
  std::uint64_t generation_ = 0;
  std::future<std::shared_ptr<PanoramaTables>> remount_;  // being built
  std::vector<cv::Mat> corrected_;     // this set's frames (headers) that colour correction sees
  std::vector<cv::Mat> stitched_;      // this set's frames (headers), black for missing cameras
  std::vector<DmabufPlanes> dmabufs_;  // where those lie in DMABUFs
  PixelFormat format_ = PixelFormat::kBgr;                       // the one both hold this set
  std::array<std::vector<cv::Mat>, kPixelFormats> blackFrames_;  // per PixelFormat, per camera
  cv::Mat panorama_;
  // buildView()'s and remount()'s threads; last, so that they are joined before what they read
  // goes.
  std::vector<std::jthread> builds_;
};

}  // namespace surroundd::daemon
