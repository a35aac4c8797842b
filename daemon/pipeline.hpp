#pragma once
// The pipeline: cameras -> synchronizer -> stages -> outputs. The stages (pipeline_stage.hpp:
// camera health, recordings, the mosaic, the panorama, the surround views, the streams' outputs)
// do the work on each frame set; the pipeline keeps their order, the clock and the report.
//
// Threads and bounded queues, stage by stage:
//   capture   one thread per camera (CameraStream), a queue of capture.queue_frames each;
//   sync .. render  this thread: synchronizes, composes the mosaic, stitches and colour-corrects
//             the panorama (split over the work pool of pipeline.threads, only when an output shows
//             it), renders the surround views (OpenGL ES; the EGL context, opened on a thread
//             of its own while the cameras open, is then current on the thread that constructs
//             the pipeline, which must be the one that runs it). A view's read-back
//             is collected while the next frame set is stitched, so its output gets each picture
//             one frame set later;
//   outputs   one thread per output that may block (QueuedSink): a video encoder (3 pictures
//             deep), an HTTP page's JPEG encoder, a window, a display's page flips (1 deep each).
// Live, only the newest complete set is processed (latest wins: an
// older one waiting is counted as stale and dropped, and so is the oldest picture an encoder has
// not taken yet); a replay processes every set and waits for its slowest output.
// Construction opens every source and output and throws (CaptureError, EncoderError,
// std::runtime_error) with a message naming the camera or file; run() does not throw for faults of
// single cameras or outputs: a failing camera ends its stream, a failing output is logged and
// dropped, the rest go on.

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/camera_stream.hpp"
#include "capture/synchronizer.hpp"
#include "common/work_pool.hpp"
#include "daemon/config/config.hpp"
#include "daemon/pipeline_outputs.hpp"
#include "daemon/pipeline_report.hpp"
#include "daemon/pipeline_stage.hpp"
#include "daemon/stage_times.hpp"

namespace surroundd::daemon {

class SurroundRenderer;
class MountCorrections;
class SurroundViews;

struct RunSummary {
  std::uint64_t frameSets = 0;
  std::chrono::duration<double> wallTime{0};
  capture::SyncStats sync;
  std::vector<std::string> cameraNames;
  std::vector<capture::CameraStreamStats> cameras;
  std::vector<std::string> outputs;  // what each output wrote
  std::uint64_t failedOutputs = 0;
  std::uint64_t failedSets = 0;  // frame sets a stage failed on: dropped, the run went on
  bool rebuild = false;          // ended because kRebuildAfterFailures sets failed in a row
  std::array<std::chrono::nanoseconds, kStageCount> stageTime{};  // summed over the run
  std::string renderer;   // the EGL context's description, when there were surround outputs
  PipelineReport report;  // at the end: per-stage and latency distributions among others

  double framesPerSecond() const {
    return wallTime.count() > 0 ? static_cast<double>(frameSets) / wallTime.count() : 0.0;
  }
};

class Pipeline;

// Hears from the pipeline thread as it loops: at least every 200 ms, whether frame sets come or
// not, so that it can answer requests (report(), setView(), latestPicture()) and feed a watchdog.
class PipelineObserver {
 public:
  virtual ~PipelineObserver() = default;
  virtual void onLoop(Pipeline& pipeline, std::chrono::steady_clock::time_point now,
                      std::uint64_t frameSets) = 0;
  // The run is ending; the outputs are about to be finalized.
  virtual void onStopping() = 0;
  // Each frame set, before its stages; it counts as one of them (an exception drops the set).
  virtual void onFrameSet(Pipeline& /*pipeline*/, const capture::FrameSet& /*set*/) {}
};

class Pipeline {
 public:
  // `start`: where the run's start-up time (to its first picture out) counts from; by default,
  // this construction, which opens the cameras and outputs and builds or loads the LUT.
  explicit Pipeline(const Config& config, RunStart start = {});
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  // A frame set that any stage fails on (an exception) is dropped, counted and logged (at most
  // once a second with the count since); after this many in a row the run ends asking to be
  // rebuilt (RunSummary::rebuild), as a state gone bad is more likely than bad frames.
  static constexpr int kRebuildAfterFailures = 20;

  // Runs until every camera has ended or `stop` becomes true, then finalizes every output.
  RunSummary run(const std::atomic<bool>& stop, PipelineObserver* observer = nullptr);

  // From the pipeline thread (an observer), while it runs:
  // Switches every surround output to `view` (takes effect with the next frame set).
  void setView(ViewKind view) { outputs_.setView(view); }
  // The vehicle's signals as they are now, for the guidelines the surround views draw.
  void setVehicleSignals(const vehicle::VehicleSignals& signals);
  PipelineReport report() const;
  // The calibration watch's mount corrections (daemon/mount_corrections.hpp); null where the
  // panorama is not made.
  MountCorrections* mountCorrections() { return mounts_; }
  // Whether any output (or recording) works: with none, the run records nothing (a full disk),
  // and the service stops feeding the watchdog and says so in its status. A failed output is
  // retried (PipelineOutputs).
  bool outputsWork() const { return outputs_.anyWorks(); }
  // The newest picture handed to the first output that shows pictures (a surround view if there
  // is one; one shown on the GPU is read back now); a header over the pipeline's buffer, valid
  // until the next frame set. Empty before.
  cv::Mat latestPicture();

 private:
  using Clock = std::chrono::steady_clock;

  // The picture a stage makes for outputs of `stream`.
  std::optional<StreamPicture> streamPicture(OutputStream stream) const;
  void openOutputs(const Config& config);
  void fillNeeds(const std::atomic<bool>& stop);
  // The next complete set; with latestWins_, the newest, the older ones counted as stale.
  std::optional<capture::FrameSet> nextSet(const std::atomic<bool>& stop);
  void process(const capture::FrameSet& set);
  Clock::time_point captureTimeOf(const capture::FrameSet& set) const;
  // Drops a set a stage failed on; true when the run should end for a rebuild.
  bool dropFailedSet(const std::exception& error);
  void finish(RunSummary& summary);
  // Logs the start-up time once, when the first picture has gone out.
  void logFirstPicture();

  RunStart runStart_;  // first: it is taken before the cameras open
  bool firstPictureLogged_ = false;
  // Opened beside the cameras and the panorama stage, taken by the surround stage; before the
  // cameras, so that a camera that cannot open leaves it to finish and go.
  // (Held by pointer: the renderer is declared in its own header, not this one.)
  std::future<std::unique_ptr<SurroundRenderer>> renderer_;
  std::vector<std::unique_ptr<capture::CameraStream>> cameras_;
  capture::Synchronizer synchronizer_;
  bool live_;        // V4L2 cameras: sets go without a late camera
  bool latestWins_;  // stale sets are skipped, encoders drop their oldest picture
  capture::Timestamp lateAfter_;
  WorkPool pool_;
  // The stages (stage_list.hpp), in their order; before the outputs, whose surround views need
  // the surround stage's GL context to the end. Each reports itself (PipelineStage::report()).
  std::vector<std::unique_ptr<PipelineStage>> stages_;
  // The stage that draws the surround views, in the list too: their outputs are opened and
  // redrawn through it. Null when no output shows one.
  SurroundViews* views_ = nullptr;
  MountCorrections* mounts_ = nullptr;
  PipelineOutputs outputs_;
  StageTimes times_;
  std::array<cv::Mat, kMaxCameras> bgrBuffers_;  // FrameWork::bgr()'s, one per camera
  std::uint64_t frameSets_ = 0;
  std::uint64_t staleDropped_ = 0;
  Clock::time_point start_{};
  std::optional<Clock::time_point> firstSetAt_;  // when the pipeline began each: the first set
  Clock::time_point lastSetAt_{};                // and the last
  Clock::time_point nextPageStatus_{};
  std::uint64_t failedSets_ = 0;
  int failedInARow_ = 0;
  std::uint64_t unloggedFailures_ = 0;  // since the last logged one
  Clock::time_point lastFailureLog_{};
  std::optional<capture::Timestamp> firstTimestamp_;
  std::chrono::nanoseconds lastStreamTime_{0};
};

}  // namespace surroundd::daemon
