#include "daemon/pipeline_ends.hpp"

#include <spdlog/spdlog.h>

#include "capture/file_source.hpp"
#include "capture/libcamera_source.hpp"
#include "capture/v4l2_source.hpp"

namespace surroundd::daemon {

std::vector<std::unique_ptr<capture::CameraStream>> openCameras(const Config& config) {
  // Each camera's queue, plus one frame waiting in the synchronizer and one being composed.
  const auto poolFrames = static_cast<std::size_t>(config.capture.queueFrames) + 2;
  std::vector<std::unique_ptr<capture::CameraStream>> cameras;
  for (const auto& camera : config.cameras) {
    const auto& name = camera.calibration.name;
    std::unique_ptr<capture::FrameSource> source;
    std::string origin;
    if (camera.libcamera) {
      source = std::make_unique<capture::LibcameraSource>(name, *camera.libcamera);
      origin = fmt::format("libcamera {}", camera.libcamera->camera);
    } else if (camera.device) {
      auto device = std::make_unique<capture::V4l2Source>(name, *camera.device);
      origin = fmt::format("{} ({})", camera.device->device.string(),
                           capture::toString(device->format()));
      source = std::move(device);
    } else {
      auto settings = *camera.source;
      settings.pacing = config.capture.pacing;
      origin = settings.path.string();
      source = std::make_unique<capture::FileSource>(name, settings);
    }
    const cv::Size calibrated = camera.calibration.intrinsics.imageSize;
    if (source->frameSize() != calibrated) {
      throw std::runtime_error(
          fmt::format("camera '{}': {} has {}x{} frames but the lens is calibrated for {}x{}", name,
                      origin, source->frameSize().width, source->frameSize().height,
                      calibrated.width, calibrated.height));
    }
    spdlog::info("camera '{}': {} ({}x{}, {:.2f} fps)", name, origin, source->frameSize().width,
                 source->frameSize().height,
                 1e9 / static_cast<double>(source->nominalPeriod().count()));
    cameras.push_back(std::make_unique<capture::CameraStream>(name, std::move(source), poolFrames,
                                                              config.capture.recovery));
  }
  return cameras;
}

std::vector<std::string> cameraNames(const Config& config) {
  std::vector<std::string> names;
  for (const auto& camera : config.cameras) names.push_back(camera.calibration.name);
  return names;
}

void setUpHealthChecks(const Config& config,
                       const std::vector<std::unique_ptr<capture::CameraStream>>& cameras,
                       capture::CameraHealthMonitor& health) {
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    const FrozenCheck check = config.cameras[c].frozenCheck;
    const bool still = cameras[c]->repeatsOnePicture();
    const bool on = check == FrozenCheck::kOn || (check == FrozenCheck::kAuto && !still);
    health.setFrozenCheck(c, on);
    if (!on) {
      spdlog::info(
          "camera '{}': not checked for frozen pictures ({})", cameras[c]->name(),
          check == FrozenCheck::kOff ? "health.frozen_check: off" : "a still picture, looped");
    }
  }
}

}  // namespace surroundd::daemon
