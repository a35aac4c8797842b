#pragma once
// The surround views: the panorama textured onto the bowl / flat / 360 mesh around the car model
// (render/surround_scene.hpp), drawn with OpenGL ES into each surround output's own view. A view's
// picture is drawn while the next set is stitched and collected when that set comes, so each
// output gets it one set later; or sooner, when the pipeline has no set to work on and the picture
// is finished (deliverFinished()). The last one goes out when the run ends.
//
// Views that do not move (top, 360, and orbit and split with a still eye; render.view_lut) are
// not drawn per set: the first time an output shows one (on a paced or live rig, once the first
// picture has gone out), or as a switch to it begins, the renderer maps where each of its pixels
// samples the panorama and draws the car and background once, and the panorama stage composes
// the view's table from that on a thread of its own, while the renderer draws the view as it
// draws those that move. From then on the panorama stage gathers its picture from the camera
// frames (PanoramaStage::ViewPicture), the car and background are laid where it shows no panorama
// and the split view's camera picture is scaled into its half, then it is corrected and the
// guidelines laid over it; for an output that encodes it, it is converted to I420 in the
// correction's pass (processing/stitch/i420_picture.hpp). The output gets it in the same set. Kept
// for when the output shows that view again.
//
// With processing.backend gpu (or auto on a hardware renderer) the panorama the views sample is
// stitched and colour-corrected on the GPU (render/gpu_stitcher.hpp) from the set's frames in
// their own format, and every view is drawn by OpenGL from it (a GPU draws a fixed view faster
// than the CPU gathers it). The CPU's panorama is then made only when something needs it: an
// output of the panorama, or a set with a faulty camera (whose part the CPU marks).
//
// Threads: the renderer (its EGL context and scene) is opened on a thread of its own
// (openSurroundRenderer()) while the cameras open and the panorama's table is read, and handed to
// the stage with its context current on no thread; the stage makes it current on the thread that
// constructs it, which must be the one that runs it.

#include <array>
#include <chrono>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "daemon/config/config.hpp"
#include "daemon/duration_histogram.hpp"
#include "daemon/pipeline_stage.hpp"
#include "daemon/stages/panorama_stage.hpp"
#include "daemon/stages/surround_renderer.hpp"
#include "daemon/surround_views.hpp"
#include "render/egl_context.hpp"
#include "render/gpu_stitcher.hpp"
#include "render/gpu_timer.hpp"
#include "render/surround_scene.hpp"
#include "render/surround_view.hpp"
#include "vehicle/vehicle_signals.hpp"

namespace surroundd::daemon {

class SurroundStage final : public PipelineStage, public SurroundViews {
 public:
  // Draws with `renderer` (openSurroundRenderer(config)), its context made current here;
  // `panorama` must outlive the stage. The GPU stitch, where processing.backend chooses it, is
  // built for frames held in `cameraFormat` (and built again should a set's frames come in
  // another). Throws RenderError.
  SurroundStage(const Config& config, SurroundRenderer renderer, PanoramaStage& panorama,
                PixelFormat cameraFormat);

  // SurroundViews (daemon/surround_views.hpp).
  std::unique_ptr<render::SurroundView> makeView(cv::Size size, ViewKind view) override;
  void prepare(PipelineOutputs& outputs, bool waitForTables) override;
  cv::Mat redraw(PipelineOutputs::PictureOutput& output) override;
  render::EglContext& context() override { return *gl_; }
  // The guidelines are drawn again only when they change by a tenth of a degree or more.
  void setVehicleSignals(const vehicle::VehicleSignals& signals) override;

  // Whether this set needs the CPU's panorama (Need::kPanorama): a view drawn from it (on the
  // CPU backend, or in a set the GPU does not stitch) that is not yet gathered through its own
  // table.
  bool needs(Need what, const FrameWork& work) const override;
  // Each output's view that does not move starts being mapped here the first time it is shown (a
  // view switched to, as the switch begins), and is gathered through its table once made.
  void process(FrameWork& work, StageTimes& times) override;
  void finish(PipelineOutputs& outputs) override;
  // Hands over the pictures whose drawing has finished, so that a picture goes out as soon as it
  // is drawn rather than when the next set comes.
  void idle(PipelineOutputs& outputs, StageTimes& times) override {
    deliver(outputs, &times, Pending::kFinished);
  }
  // The renderer, and the GPU's times of its steps.
  void report(PipelineReport& report) const override;

  // The renderer, and where the panorama is stitched when that is the GPU.
  std::string description() const {
    return gpu_ ? gl_->description() + "; panorama stitched on the GPU" : gl_->description();
  }
  // Whether the GPU stitches the panorama (processing.backend as it came out on this renderer).
  bool stitchesOnGpu() const { return gpu_ != nullptr; }
  // Why the GPU stitch cannot import camera frames from their DMABUFs (render/dmabuf_import.hpp);
  // empty when it can.
  const std::string& dmabufImportRefusal() const { return importRefusal_; }

 private:
  enum class Pending { kAll, kFinished };
  // Hands each view's pending picture (the previous set's; or only those finished) to its output.
  void deliver(PipelineOutputs& outputs, StageTimes* times, Pending which = Pending::kAll);

  // A fixed view's picture, and the renderer's car and background to lay over it.
  struct FixedView {
    // None while its table is being made, or where that failed.
    std::unique_ptr<PanoramaStage::ViewPicture> view;
    // Its table being made, until taken into `view`; and how long OpenGL's part of that took.
    std::future<std::unique_ptr<PanoramaStage::ViewPicture>> building;
    std::chrono::duration<double> mappedIn{0};
    cv::Mat overlay;                       // 8-bit BGR, the renderer's picture of the view
    cv::Mat overlayMask;                   // CV_8U: where it shows no panorama
    cv::Mat picture;                       // the last drawn
    cv::Mat i420;                          // and in I420, for an output that takes that
    bool inI420 = false;                   // whether `i420` is the picture its output gets
    std::chrono::nanoseconds drawnAt{-1};  // the stream time of its set
    bool handOver = false;                 // drawn this set for its output
    cv::Mat guides;                        // the guidelines as the view shows them, on black
    cv::Mat guidesGrey;
    cv::Mat guidesMask;      // CV_8U: where they are
    int guidesVersion = -1;  // of SurroundStage::guidesVersion_
  };
  // Lays the guidelines (the scene has some) over a fixed view's picture, drawing them again when
  // they have changed.
  void layGuidelines(render::SurroundView& view, FixedView& fixed);
  // The output's fixed view, its building started the first time it shows it; null until built
  // and the switch to it has ended, for a view that moves, with render.view_lut off, on the GPU
  // backend, or where the renderer cannot map views (said once).
  FixedView* fixedView(render::SurroundView& view);
  // The output's fixed view, as fixedView(); none for a sink that shows the view on the GPU.
  FixedView* fixedViewFor(PipelineOutputs::PictureOutput& output);
  // The fixed view the output shows now, as fixedViewFor() gives it once taken into use; with
  // nothing started or taken.
  const FixedView* shownFixedView(const PipelineOutputs::PictureOutput& output) const;
  // Maps the view onto the panorama (OpenGL, here), then has the panorama stage build its table.
  void startFixedView(render::SurroundView& view, FixedView& fixed);
  // Whether the GPU stitches this set: the GPU backend, and no camera faulty.
  bool gpuStitches(const FrameWork& work) const;
  // The set's panorama into the texture the scene samples: stitched on the GPU, or the CPU's
  // uploaded.
  void stitchOnGpu();
  // Which way each camera's lent frames reached the GPU (imported, or uploaded and why), when it
  // changes.
  void sayHowFramesReachTheGpu();
  void uploadPanorama();
  // The GPU times of the runs finished since the last call into gpuTimes_.
  void collectGpuTimes();

  render::ViewSettings views_;
  // The context first, so that it outlives the GL objects of the scene (and of the outputs' views,
  // which the pipeline destroys before its stages).
  std::unique_ptr<render::EglContext> gl_;
  std::unique_ptr<render::SurroundScene> scene_;
  render::GpuTimer gpuTimer_;  // borrowed by the outputs' views
  // The GPU's own time of each run of its steps so far (render/gpu_timer.hpp), read a set or two
  // after the run; none where the driver cannot time them.
  std::array<DurationHistogram, render::kGpuSteps> gpuTimes_{};
  PanoramaStage& panoramaStage_;
  const cv::Mat& panorama_;
  std::unique_ptr<render::GpuStitcher> gpu_;  // processing.backend: gpu
  std::string importRefusal_;
  std::vector<char> importSaid_;  // per camera: 0 nothing said, 1 imported, 2 uploaded
  bool panoramaOnGpu_ = false;    // the scene samples gpu_'s panorama (the last set's)
  bool viewLut_;
  GuidelineMode guidelineMode_;
  render::GuidelineSettings guide_;
  processing::VehicleDimensions car_;
  std::vector<render::GuidelineVertex> guideVertices_;  // reserved at start: filled in place
  // What the guidelines show now (travel, steering in tenths of a degree); none: not shown.
  std::optional<std::pair<render::Travel, long>> guidesShown_;
  int guidesVersion_ = 0;
  bool tablesAfterFirstPicture_ = false;  // prepare() without waiting: no table started yet
  // Per output's view (its address; each lives as long as the pipeline) and the kind it shows.
  std::map<std::pair<const render::SurroundView*, ViewKind>, FixedView> fixedViews_;
  std::size_t splitCamera_ = 0;
  std::chrono::nanoseconds lastStreamTime_{0};
};

}  // namespace surroundd::daemon
