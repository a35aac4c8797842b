#pragma once
// The pipeline's stages, in their order, built from the config: the one place that names them. A
// new stage is its own files (daemon/stages/) and one line in buildStages().

#include <future>
#include <memory>
#include <vector>

#include "capture/camera_stream.hpp"
#include "capture/synchronizer.hpp"
#include "common/work_pool.hpp"
#include "daemon/config/config.hpp"
#include "daemon/mount_corrections.hpp"
#include "daemon/pipeline_stage.hpp"
#include "daemon/stages/surround_renderer.hpp"
#include "daemon/surround_views.hpp"

namespace surroundd::daemon {

// What the stages are built from besides the config; each must outlive them.
struct StageSources {
  std::vector<std::unique_ptr<capture::CameraStream>>& cameras;
  capture::Synchronizer& synchronizer;
  WorkPool& pool;
  // The surround views' renderer being opened (openSurroundRenderer()), where an output shows
  // them; taken by their stage.
  std::future<std::unique_ptr<SurroundRenderer>>& renderer;
};

struct StageList {
  std::vector<std::unique_ptr<PipelineStage>> stages;
  // The stage that draws the surround views, where an output shows them; else null.
  SurroundViews* views = nullptr;
  // The calibration watch's mount corrections, where it watches; else null.
  MountCorrections* mounts = nullptr;
};

// Throws what each stage's set-up throws (std::runtime_error naming the config, RenderError).
StageList buildStages(const Config& config, const StageSources& sources);

}  // namespace surroundd::daemon
