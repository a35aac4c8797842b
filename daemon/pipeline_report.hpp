#pragma once
// What the pipeline can say about itself while it runs: the one-line status (log, systemd STATUS=),
// the longer status of `surroundctl status`, and the Prometheus text of `surroundctl metrics`.
// A PipelineReport is a plain copy made on request, so formatting never touches the live pipeline.

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "capture/camera_health.hpp"
#include "capture/camera_stream.hpp"
#include "capture/synchronizer.hpp"
#include "daemon/duration_histogram.hpp"
#include "processing/rig.hpp"
#include "render/gpu_timer.hpp"

namespace surroundd::daemon {

// Where the pipeline thread's time goes, per frame set: each kind of work, whichever pipeline
// stage does it (the panorama's stitch and a fixed view's gather are both "stitch"). "sync" is
// the wait for a set's frames and the check of its cameras' health; "watch" the drift watch's
// measurements.
enum class Stage { kSync, kMosaic, kStitch, kCorrect, kWatch, kRender, kReadBack, kOutput, kCount };
inline constexpr std::size_t kStageCount = static_cast<std::size_t>(Stage::kCount);
const char* toString(Stage stage);

// Where a run's start-up time (to its first picture out) counts from: the process's start (the
// service's first run), a reload's acceptance (the gap a reload leaves in the pictures, the old
// run's finalizing included), or the pipeline's construction (a rebuild after failures, the
// benchmark, the tests).
enum class StartupFrom { kProcess, kReload, kPipeline };
const char* toString(StartupFrom from);  // "process", "reload", "pipeline"

struct RunStart {
  std::chrono::steady_clock::time_point at = std::chrono::steady_clock::now();
  StartupFrom from = StartupFrom::kPipeline;
};

// One seam of the calibration-drift watch: how far apart its two cameras put the ground under it.
struct SeamReport {
  std::string name;               // "front/left"
  std::optional<double> shiftCm;  // none: not measured yet, or the ground could not be compared
  double distanceM = 0;           // of the compared ground from the vehicle's centre
  double response = 0;
  bool misaligned = false;
  // With calibration_watch.correct: suggest or apply, where the suggested mounts would put it, over
  // the ground compared since start.
  std::optional<double> suggestedCm{};
};

// What the calibration watch would turn a camera's mount by (calibration_watch.correct).
struct MountSuggestion {
  processing::MountAngles changeDeg;
  double heightCm = 0;
  double sigmaDeg = 0;  // the largest of the angles' uncertainties
  // Past MountRefinementResult::kLargestTurnDeg: the camera has moved too far to be followed (a
  // fault, reported: check its mount), not a correction to make.
  bool fault = false;
};

// The mount refinement behind the suggestions: how much ground it has compared, at what cost.
struct MountWatchReport {
  std::size_t setsCompared = 0;
  std::size_t comparisons = 0;  // of ground patches, kept in the last solution
  double cpuSeconds = 0;        // of its own thread
  bool applying = false;        // correct: apply
  // Corrections made and taken back, and whether the last is being checked.
  std::size_t applied = 0, reverted = 0;
  bool checking = false;
};

// One seam of the colour correction, as the last set left it.
struct ColourSeamReport {
  std::string name;  // "front/right": the seam's source camera, then its target
  // Median over its measured blocks of the mean over channels of |target - source|, in levels.
  double stepUncorrected = 0, stepCorrected = 0;
  int blocks = 0, clampedBlocks = 0;  // clamped: the field hit gain_range there
  // Stretches the correction would have made worse than none, left as they were.
  int blocksLeftAsTheyWere = 0;
  bool leftAsItWas = false;  // the whole seam
};

// The colour correction (colour_correction.method: poisson), as the last set left it.
struct ColourReport {
  bool balanced = false;  // colour_correction.balance
  std::vector<ColourSeamReport> seams;
  // With the balance, per camera (the report's cameras' order), its B G R gains.
  std::vector<std::array<float, 3>> balanceGains;
};

struct CameraReport {
  std::string name;
  capture::CameraHealth health = capture::CameraHealth::kOk;
  capture::CameraStreamStats stats;
  std::size_t queued = 0;  // frames waiting between its capture thread and the synchronizer
  bool calibrationDrifting = false;  // the drift watch's verdict
  std::optional<MountSuggestion> mountSuggestion{};
};

// The last switch of view (Pipeline::setView, or an output's page): from its request to the first
// picture drawn after it, and to the first picture of every switched output showing the new view
// settled (its transition over); `settled` is empty while the switch is under way.
struct ViewSwitchTime {
  std::chrono::duration<double> first{0};
  std::optional<std::chrono::duration<double>> settled;
};

struct PipelineReport {
  std::chrono::duration<double> elapsed{0};
  // From the first frame set to one nominal frame period after the last, or to now if that is
  // later: the time the sets so far took, so that a rig delivering exactly its frame rate is
  // measured at it (from the run's start, or to now, it would read a little under). 0 before the
  // first set.
  std::chrono::duration<double> setSpan{0};
  std::uint64_t frameSets = 0;
  std::uint64_t staleDropped = 0;  // live: complete sets skipped because a newer one was ready
  capture::SyncStats sync;
  std::vector<CameraReport> cameras;
  std::vector<capture::HealthChange>
      healthChanges;                           // every one so far, in order; `at`: stream time
  std::vector<SeamReport> seams;               // the drift watch's; empty when it is off
  std::optional<MountWatchReport> mountWatch;  // with calibration_watch.correct: suggest, apply
  std::optional<ColourReport> colour;          // with colour_correction.method: poisson
  std::array<DurationHistogram, kStageCount> stages;  // per frame set that went through the stage
  DurationHistogram latency;  // a frame's capture to its picture handed to an output
  // From the run's start to its first picture handed to an output; empty before.
  std::optional<std::chrono::duration<double>> startup;
  StartupFrom startupFrom = StartupFrom::kPipeline;
  std::optional<ViewSwitchTime> viewSwitch;  // empty before the first switch's first picture
  std::size_t outputs = 0;
  std::uint64_t failedOutputs = 0;
  std::uint64_t failedSets = 0;     // frame sets a stage failed on (dropped)
  std::uint64_t outputDropped = 0;  // pictures outputs dropped because they fell behind
  std::string renderer;
  // The GPU's own time of each run of its steps (upload, stitch, draw, read-back), where the
  // renderer can time them (GL_EXT_disjoint_timer_query): `gpuTimed`.
  bool gpuTimed = false;
  std::array<DurationHistogram, render::kGpuSteps> gpuSteps;

  double framesPerSecond() const {
    return setSpan.count() > 0 ? static_cast<double>(frameSets) / setSpan.count() : 0.0;
  }
};

// "20.9 fps, 0 frames dropped by sync, mean skew 1.7 ms; front ok, right black, ..."
std::string statusLine(const PipelineReport& report);
// The status line, then one line per stage with p50/p99, the frame rate, latency and first
// picture beside their limits, and one line per camera.
std::string statusText(const PipelineReport& report);
// The calibration watch alone (surroundctl calibration status): each seam's figure, the mount
// refinement's work, and per camera whether it drifts and the mount correction suggested or the
// fault found.
std::string calibrationText(const PipelineReport& report);
// For the HTTP page: {"fps": .., "frames": .., "cameras": {"front": "ok", ..}, "latency_ms": ..,
// "dropped_by_sync": ..}.
std::string statusJson(const PipelineReport& report);
// The figures beside their limits (compliance_limits.hpp), as the status and the benchmark print
// them. "30.1 fps (ISO 16505 / IEC 63033-3: >= 30 fps, met)"
std::string frameRateWithLimit(double framesPerSecond);
// "p50 41.2 ms  p99 84.0 ms (ISO 16505 / IEC 63033-3: p99 < 200 ms, met)"
std::string latencyWithLimit(const DurationHistogram& latency);
// "0.62 s after the process started (FMVSS 111: <= 2.0 s, met; target <= 1.0 s, met)"
std::string startupWithLimits(std::chrono::duration<double> startup, StartupFrom from);
// "first picture 0.04 s, settled 0.45 s after the request (FMVSS 111: <= 2.0 s, met; target <=
// 0.5 s, met)", or "under way, first picture 0.04 s after the request"
std::string viewSwitchWithLimits(const ViewSwitchTime& time);

// Prometheus text exposition format (version 0.0.4), metric names prefixed surroundd_.
std::string prometheusText(const PipelineReport& report);

}  // namespace surroundd::daemon
