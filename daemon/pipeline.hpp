#pragma once
// The replay pipeline as it stands: cameras -> synchronizer -> mosaic and/or panorama -> surround
// views -> outputs.
//
// One capture thread per camera (CameraStream); this thread synchronizes, composes the mosaic,
// stitches and colour-corrects the panorama (on the work pool, only when an output shows it),
// renders the surround views (OpenGL ES; the EGL context is made current on the thread that
// constructs the pipeline, which must be the one that runs it) and feeds the outputs. A surround
// view's read-back is collected while the next frame set is stitched, so its output gets each
// picture one frame set later.
// Construction opens every source and output and throws (CaptureError, EncoderError,
// std::runtime_error) with a message naming the camera or file; run() does not throw for faults of
// single cameras or outputs: a failing camera ends its stream, a failing output is logged and
// dropped, the rest go on.

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "capture/camera_health.hpp"
#include "capture/camera_stream.hpp"
#include "capture/synchronizer.hpp"
#include "common/work_pool.hpp"
#include "daemon/config.hpp"
#include "daemon/rig_recorder.hpp"
#include "daemon/service_notifier.hpp"
#include "processing/gain_compensation.hpp"
#include "processing/panorama_ownership.hpp"
#include "processing/poisson_correction.hpp"
#include "processing/stitcher.hpp"
#include "render/egl_context.hpp"
#include "render/frame_sink.hpp"
#include "render/mosaic.hpp"
#include "render/surround_scene.hpp"
#include "render/surround_view.hpp"

namespace surroundd::daemon {

// Where the pipeline thread's time goes, summed over the run.
enum class Stage { kSync, kMosaic, kStitch, kCorrect, kRender, kReadBack, kOutput, kCount };
const char* toString(Stage stage);

struct RunSummary {
  std::uint64_t frameSets = 0;
  std::chrono::duration<double> wallTime{0};
  capture::SyncStats sync;
  std::vector<std::string> cameraNames;
  std::vector<capture::CameraStreamStats> cameras;
  std::vector<std::string> outputs;  // what each output wrote
  std::uint64_t failedOutputs = 0;
  std::array<std::chrono::nanoseconds, static_cast<std::size_t>(Stage::kCount)> stageTime{};
  std::vector<capture::HealthChange> healthChanges;  // in order; `at` is stream time
  std::string renderer;  // the EGL context's description, when there were surround outputs

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
  // `service`, when given, hears of readiness, progress (watchdog) and status.
  RunSummary run(const std::atomic<bool>& stop, ServiceNotifier* service = nullptr);

  // Switches every surround output to `view` (takes effect with the next frame set).
  void setView(ViewKind view);

 private:
  struct Output {
    OutputStream stream = OutputStream::kMosaic;
    std::unique_ptr<render::FrameSink> sink;     // null once it failed
    std::unique_ptr<render::SurroundView> view;  // surround outputs
    std::chrono::nanoseconds pendingTime{0};     // stream time of the view's pending picture
  };

  void fillNeeds(const std::atomic<bool>& stop);
  // "20.9 fps, 0 frames dropped by sync, mean skew 1.7 ms; front ok, right black, ..."
  std::string statusLine(std::uint64_t frameSets, std::chrono::duration<double> elapsed) const;
  void process(const capture::FrameSet& set);
  void followHealth(const capture::FrameSet& set);
  void renderSurround(const capture::FrameSet& set, std::chrono::nanoseconds streamTime);
  void deliverSurround();
  void finish(RunSummary& summary);
  // Runs `step` on the output; an exception drops the output with a logged error.
  template <typename Step>
  void guarded(Output& output, Step&& step);
  void timed(Stage stage, std::chrono::steady_clock::time_point& since);
  const cv::Mat& imageOf(OutputStream stream) const;
  bool shows(OutputStream stream) const;  // a working output shows it
  void setUpColourCorrection(const Config& config);
  void setUpSurround(const Config& config);

  std::vector<std::unique_ptr<capture::CameraStream>> cameras_;
  capture::Synchronizer synchronizer_;
  bool live_;  // V4L2 cameras: sets go without a late camera
  capture::Timestamp lateAfter_;
  capture::CameraHealthMonitor health_;
  std::array<const char*, capture::kMaxCameras> faults_{};  // per camera: what is wrong, or null
  std::vector<capture::HealthChange> healthChanges_;
  WorkPool pool_;
  render::Mosaic mosaic_;
  cv::Mat canvas_;                                  // the composed mosaic; reused for every set
  std::unique_ptr<processing::PanoramaLut> lut_;    // set when an output shows the panorama
  std::unique_ptr<processing::Stitcher> stitcher_;  // borrows *lut_ and pool_
  std::unique_ptr<processing::PoissonColourCorrection> poisson_;  // colour_correction: poisson
  std::unique_ptr<processing::GainCompensation> gains_;           // colour_correction: gain
  std::unique_ptr<processing::PanoramaOwnership> ownership_;      // marks faulty cameras
  std::vector<cv::Mat> frames_;        // this set's images (headers only); empty where missing
  std::vector<cv::Mat> stitchInputs_;  // the same, with black frames for missing cameras
  std::vector<cv::Mat> blackFrames_;
  cv::Mat panorama_;
  // Surround outputs: the context first, so that it outlives the GL objects below.
  std::unique_ptr<render::EglContext> gl_;
  std::unique_ptr<render::SurroundScene> scene_;
  std::size_t splitCamera_ = 0;
  std::vector<Output> outputs_;
  std::vector<std::unique_ptr<RigRecorder>> recorders_;  // null once failed
  std::array<std::chrono::nanoseconds, static_cast<std::size_t>(Stage::kCount)> stageTime_{};
  std::uint64_t failedSinks_ = 0;
  std::optional<capture::Timestamp> firstTimestamp_;
  std::chrono::nanoseconds lastStreamTime_{0};
};

}  // namespace surroundd::daemon
