#pragma once
// An output of every frame set's camera frames as captured, rather than of a picture the pipeline
// makes (OutputInput::kCameraFrames in output_type.hpp): a recording (RigRecorder).
//
// Error policy as render::FrameSink's: record() and finish() throw naming the file; the pipeline
// logs the failure and drops that output, the others go on.

#include <string>

#include "capture/frame_set.hpp"

namespace surroundd::daemon {

class CameraFramesSink {
 public:
  virtual ~CameraFramesSink() = default;
  CameraFramesSink() = default;
  CameraFramesSink(const CameraFramesSink&) = delete;
  CameraFramesSink& operator=(const CameraFramesSink&) = delete;

  // Each camera's frame of the set (an empty slot is a camera without one).
  virtual void record(const capture::FrameSet& set) = 0;
  // The run is over: finalize what was written.
  virtual void finish() = 0;
  // What was written, for the log.
  virtual std::string describe() const = 0;
};

}  // namespace surroundd::daemon
