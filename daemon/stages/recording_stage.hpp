#pragma once
// Hands every frame set's camera frames, as captured, to the recordings (OutputInput::
// kCameraFrames outputs), before any other stage can fail on the set.

#include "daemon/pipeline_stage.hpp"

namespace surroundd::daemon {

class RecordingStage final : public PipelineStage {
 public:
  void process(FrameWork& work, StageTimes& times) override {
    work.outputs.record(work.set);
    times.lap(Stage::kOutput);
  }
};

}  // namespace surroundd::daemon
