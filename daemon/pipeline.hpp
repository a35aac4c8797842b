#pragma once
// The replay pipeline as it stands: cameras -> synchronizer -> mosaic and/or panorama -> outputs.
//
// One capture thread per camera (CameraStream); this thread synchronizes, composes the mosaic,
// stitches and colour-corrects the panorama (on the work pool, only when an output shows it) and
// feeds the outputs.
// Construction opens every source and output and throws (CaptureError, EncoderError,
// std::runtime_error) with a message naming the camera or file; run() does not throw for faults of
// single cameras or outputs: a failing camera ends its stream, a failing output is logged and
// dropped, the rest go on.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "capture/camera_stream.hpp"
#include "capture/synchronizer.hpp"
#include "common/work_pool.hpp"
#include "daemon/config.hpp"
#include "processing/gain_compensation.hpp"
#include "processing/poisson_correction.hpp"
#include "processing/stitcher.hpp"
#include "render/frame_sink.hpp"
#include "render/mosaic.hpp"

namespace surroundd::daemon {

struct RunSummary {
  std::uint64_t frameSets = 0;
  std::chrono::duration<double> wallTime{0};
  capture::SyncStats sync;
  std::vector<std::string> cameraNames;
  std::vector<capture::CameraStreamStats> cameras;
  std::vector<std::string> outputs;  // what each output wrote
  std::uint64_t failedOutputs = 0;

  double framesPerSecond() const {
    return wallTime.count() > 0 ? static_cast<double>(frameSets) / wallTime.count() : 0.0;
  }
};

class Pipeline {
 public:
  explicit Pipeline(const Config& config);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  // Runs until every camera has ended or `stop` becomes true, then finalizes every output.
  RunSummary run(const std::atomic<bool>& stop);

 private:
  void fillNeeds(const std::atomic<bool>& stop);
  void render(const capture::FrameSet& set);
  void finish(RunSummary& summary);

  struct Output {
    OutputStream stream;
    std::unique_ptr<render::FrameSink> sink;  // null once it failed
  };
  const cv::Mat& imageOf(OutputStream stream) const;
  void setUpColourCorrection(const Config& config);

  std::vector<std::unique_ptr<capture::CameraStream>> cameras_;
  capture::Synchronizer synchronizer_;
  WorkPool pool_;
  render::Mosaic mosaic_;
  cv::Mat canvas_;                                  // the composed mosaic; reused for every set
  std::unique_ptr<processing::PanoramaLut> lut_;    // set when an output shows the panorama
  std::unique_ptr<processing::Stitcher> stitcher_;  // borrows *lut_ and pool_
  std::unique_ptr<processing::PoissonColourCorrection> poisson_;  // colour_correction: poisson
  std::unique_ptr<processing::GainCompensation> gains_;           // colour_correction: gain
  std::vector<cv::Mat> frames_;        // this set's images (headers only); empty where missing
  std::vector<cv::Mat> stitchInputs_;  // the same, with black frames for missing cameras
  std::vector<cv::Mat> blackFrames_;
  cv::Mat panorama_;
  bool wantMosaic_ = false;
  std::vector<Output> outputs_;
  std::uint64_t failedSinks_ = 0;
  std::optional<capture::Timestamp> firstTimestamp_;
};

}  // namespace surroundd::daemon
