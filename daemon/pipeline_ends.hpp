#pragma once
// The pipeline's cameras, opened from the config (file replay, decoded as it plays or preloaded
// into memory; V4L2, libcamera). Its outputs are opened through their types' factories
// (output_type.hpp).
//
// Error policy: throws (CaptureError, std::runtime_error) with a message naming the camera, file or
// device that could not be opened.

#include <memory>
#include <string>
#include <vector>

#include "capture/camera_health.hpp"
#include "capture/camera_stream.hpp"
#include "daemon/config/config.hpp"

namespace surroundd::daemon {

// One CameraStream per camera (not started yet), each checked against its lens's calibrated size.
std::vector<std::unique_ptr<capture::CameraStream>> openCameras(const Config& config);
std::vector<std::string> cameraNames(const Config& config);
// Each camera's frozen check, from its `health.frozen_check` and its opened source.
void setUpHealthChecks(const Config& config,
                       const std::vector<std::unique_ptr<capture::CameraStream>>& cameras,
                       capture::CameraHealthMonitor& health);

}  // namespace surroundd::daemon
