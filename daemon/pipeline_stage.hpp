#pragma once
// One step of the pipeline thread's work on each frame set. The pipeline is a short list of
// stages (Pipeline's constructor lists them, in order): each is set up once from the config — all
// that is heavy happens then — and is then given every frame set in turn. A stage owns its state
// and says where its time goes (StageTimes); what it makes for later stages it hands them at
// set-up (a picture they read) or in the set's FrameWork, where a stage that makes something
// costly asks the later ones whether this set needs it (needs()), not naming them.
//
// Error policy: set-up throws, naming what could not be set up. An exception from process() drops
// the set (Pipeline counts it, and rebuilds after Pipeline::kRebuildAfterFailures in a row).
// Threads: the pipeline thread only.

#include <array>
#include <chrono>
#include <memory>
#include <optional>
#include <span>

#include <opencv2/core.hpp>

#include "capture/frame_set.hpp"
#include "common/camera_limit.hpp"
#include "daemon/pipeline_outputs.hpp"
#include "daemon/pipeline_report.hpp"
#include "daemon/stage_times.hpp"

namespace surroundd::daemon {

class PipelineStage;

// What a stage may ask the stages before it to make for a set (PipelineStage::needs()), where
// making it costs and not every set needs it.
enum class Need {
  kPanorama,  // the CPU's panorama picture of the set (FrameWork::panorama)
};

// A picture a stage makes for the outputs of a stream (the mosaic, the panorama): reused for every
// set, of `size`.
struct StreamPicture {
  const cv::Mat* picture;
  cv::Size size;
};

// One frame set on its way through the stages.
struct FrameWork {
  const capture::FrameSet& set;
  // Per camera: a buffer that bgr() converts a YUV frame into, kept by the pipeline from set to set
  // (allocated at the first conversion, then reused).
  std::array<cv::Mat, kMaxCameras>& bgrBuffers;
  std::chrono::nanoseconds streamTime{0};          // since the run's first set
  std::chrono::steady_clock::time_point origin{};  // the capture time of its oldest frame
  // Per camera: what is wrong with it (its health), or null; a faulty camera's picture is marked
  // and left out of colour correction.
  std::array<const char*, kMaxCameras> faults{};
  PipelineOutputs& outputs;

  // Camera `camera`'s frame of the set as 8-bit BGR, or null where the set has none. A frame held
  // in its camera's YUV (common/pixel_format.hpp) is converted once per set, at the first call:
  // only what needs whole BGR frames asks (a camera shown as it is, the mosaic, the drift watch);
  // the stitch samples the frames as they are.
  const cv::Mat* bgr(std::size_t camera);
  std::array<const cv::Mat*, kMaxCameras> converted{};  // bgr()'s answers so far, for this set

  // Whether a stage after the one running needs `what` made for this set (asked now: what the
  // stages before have found, a faulty camera say, counts).
  bool needed(Need what) const;
  std::span<const std::unique_ptr<PipelineStage>> later{};  // set by the pipeline for each stage

  // The CPU's panorama of this set, where a stage made it (Need::kPanorama); else null.
  const cv::Mat* panorama = nullptr;
};

class PipelineStage {
 public:
  virtual ~PipelineStage() = default;
  PipelineStage() = default;
  PipelineStage(const PipelineStage&) = delete;
  PipelineStage& operator=(const PipelineStage&) = delete;

  virtual void process(FrameWork& work, StageTimes& times) = 0;
  // Whether this set needs `what` made by a stage before this one (FrameWork::needed()). Asked
  // of the later stages by the stage that would make it; it changes nothing.
  virtual bool needs(Need /*what*/, const FrameWork& /*work*/) const { return false; }
  // The picture this stage makes for the outputs of `stream`; none for a stream it does not make.
  virtual std::optional<StreamPicture> streamPicture(OutputStream /*stream*/) const {
    return std::nullopt;
  }
  // No set is waiting: hand over what has finished meanwhile rather than with the next set.
  virtual void idle(PipelineOutputs& /*outputs*/, StageTimes& /*times*/) {}
  // Adds what the stage knows to the pipeline's report, whose cameras are listed already (in the
  // rig's order).
  virtual void report(PipelineReport& /*report*/) const {}
  // The cameras have stopped and the outputs are about to be finalized: hand over what is still
  // in flight.
  virtual void finish(PipelineOutputs& /*outputs*/) {}
};

}  // namespace surroundd::daemon
