#include "daemon/stages/camera_health_stage.hpp"

#include <spdlog/spdlog.h>

#include "daemon/pipeline_ends.hpp"

namespace surroundd::daemon {

CameraHealthStage::CameraHealthStage(
    const Config& config, const std::vector<std::unique_ptr<capture::CameraStream>>& cameras,
    const capture::Synchronizer& synchronizer)
    : cameras_(cameras), synchronizer_(synchronizer), monitor_(cameras.size()) {
  setUpHealthChecks(config, cameras, monitor_);
}

void CameraHealthStage::process(FrameWork& work, StageTimes& times) {
  for (const capture::HealthChange& change : monitor_.observe(work.set, synchronizer_.stats())) {
    const auto& name = cameras_[change.camera]->name();
    const double at = std::chrono::duration<double>(work.streamTime).count();
    if (change.to == capture::CameraHealth::kOk) {
      spdlog::info("camera '{}': back to normal at {:.3f} s (was {})", name, at,
                   capture::toString(change.from));
      faults_[change.camera] = nullptr;
    } else {
      spdlog::warn("camera '{}': {} at {:.3f} s; its part of the view is marked", name,
                   capture::toString(change.to), at);
      faults_[change.camera] = capture::toString(change.to);
    }
    changes_.push_back(change);
    changes_.back().at = work.streamTime;
  }
  work.faults = faults_;
  times.lap(Stage::kSync);
}

void CameraHealthStage::report(PipelineReport& report) const {
  for (std::size_t c = 0; c < report.cameras.size(); ++c) {
    report.cameras[c].health = monitor_.health(c);
  }
  report.healthChanges = changes_;
}

}  // namespace surroundd::daemon
