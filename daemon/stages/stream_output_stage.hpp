#pragma once
// Hands the picture of each output's stream (the mosaic, the panorama) to the outputs that want
// this set's. Surround outputs get theirs from the surround stage.

#include "daemon/pipeline_stage.hpp"

namespace surroundd::daemon {

class StreamOutputStage final : public PipelineStage {
 public:
  void process(FrameWork& work, StageTimes& times) override {
    for (auto& output : work.outputs.pictures()) {
      if (output.view || !output.sink || !output.sink->wantsFrame(work.streamTime)) continue;
      work.outputs.handOver(output, *output.picture, work.streamTime, work.origin);
    }
    times.lap(Stage::kOutput);
  }
  // An output of the panorama takes it whether or not it wants this set: the run's end hands it
  // the last one.
  bool needs(Need what, const FrameWork& work) const override {
    return what == Need::kPanorama && work.outputs.shows(OutputStream::kPanorama);
  }
};

}  // namespace surroundd::daemon
