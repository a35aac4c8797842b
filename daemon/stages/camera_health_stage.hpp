#pragma once
// Follows each camera's health from the frame sets (capture/camera_health.hpp): logs each change
// and tells the later stages which cameras are faulty (FrameWork::faults), so that their part of
// the view is marked and colour correction goes without them.

#include <array>
#include <memory>
#include <vector>

#include "capture/camera_health.hpp"
#include "capture/camera_stream.hpp"
#include "capture/synchronizer.hpp"
#include "daemon/config/config.hpp"
#include "daemon/pipeline_stage.hpp"

namespace surroundd::daemon {

class CameraHealthStage final : public PipelineStage {
 public:
  // The cameras and synchronizer must outlive the stage.
  CameraHealthStage(const Config& config,
                    const std::vector<std::unique_ptr<capture::CameraStream>>& cameras,
                    const capture::Synchronizer& synchronizer);

  void process(FrameWork& work, StageTimes& times) override;
  // Each camera's health.
  void report(PipelineReport& report) const override;

 private:
  const std::vector<std::unique_ptr<capture::CameraStream>>& cameras_;
  const capture::Synchronizer& synchronizer_;
  capture::CameraHealthMonitor monitor_;
  std::array<const char*, kMaxCameras> faults_{};  // per camera: what is wrong, or null
  std::vector<capture::HealthChange> changes_;
};

}  // namespace surroundd::daemon
