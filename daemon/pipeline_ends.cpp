#include "daemon/pipeline_ends.hpp"

#include <algorithm>
#include <exception>
#include <future>
#include <span>
#include <utility>
#include <variant>

#include <spdlog/spdlog.h>

#include "capture/file_source.hpp"
#include "capture/libcamera_source.hpp"
#include "capture/preloaded_source.hpp"
#include "capture/v4l2_source.hpp"
#include "common/overloaded.hpp"
#include "daemon/live_cameras.hpp"

namespace surroundd::daemon {
namespace {

constexpr double kBytesPerMib = 1024.0 * 1024.0;

// A file preloaded into memory, allowed what capture.preload_max_mb leaves after the cameras
// preloaded before it (`before`: their names and bytes).
std::unique_ptr<capture::PreloadedSource> openPreloaded(
    const Config& config, const std::string& camera, capture::PreloadSettings settings,
    std::span<const std::pair<std::string, std::uint64_t>> before,
    std::shared_ptr<capture::ReplayStart> start) {
  settings.file.pacing = config.capture.pacing;
  const auto budget = static_cast<std::uint64_t>(config.capture.preloadMaxMb) << 20;
  std::uint64_t used = 0;
  std::string holders;
  for (const auto& [name, bytes] : before) {
    used += bytes;
    holders += fmt::format("{}'{}' {:.1f} MiB", holders.empty() ? "" : ", ", name,
                           static_cast<double>(bytes) / kBytesPerMib);
  }
  settings.maxBytes = budget - std::min(used, budget);
  settings.maxBytesOrigin = fmt::format(
      "capture.preload_max_mb: {} for every preloaded camera together{}",
      config.capture.preloadMaxMb,
      holders.empty() ? "" : fmt::format(", less what the cameras before it hold: {}", holders));
  return std::make_unique<capture::PreloadedSource>(camera, settings, std::move(start));
}

}  // namespace

std::vector<std::unique_ptr<capture::CameraStream>> openCameras(const Config& config) {
  // Each camera's queue, plus one frame waiting in the synchronizer and one being composed.
  const auto poolFrames = static_cast<std::size_t>(config.capture.queueFrames) + 2;
  struct Opened {
    std::unique_ptr<capture::FrameSource> source;
    std::string origin;
  };
  // Files and V4L2 devices open on threads of their own, all at once: a decoder finds its
  // stream's parameters by decoding (0.2 s for a 1080p H.264 file, measured here), a device sets
  // up its buffers, and one after the other they held the first picture back by their sum. A
  // preloaded file opens in turn, allowed what the cameras before it left of the preload budget;
  // libcamera cameras open in turn too (one camera manager for all, and its configuration from
  // several threads is untried here).
  std::vector<std::pair<std::string, std::uint64_t>> preloadedBytes;  // per camera so far
  // The replayed cameras play on one clock, as cameras triggered together would deliver.
  const auto replayStart = std::make_shared<capture::ReplayStart>();
  // The cameras the threads read, `device: auto` given its device: declared before the futures,
  // so that it outlives them.
  std::vector<std::string> said;
  const std::vector<RigCamera> rig = withAutoDevices(config.cameras, said);
  for (const auto& line : said) spdlog::info("{}", line);
  // After what the threads use: should one camera fail, the others' futures wait for their
  // threads as they go, before the rest of this function's locals.
  std::vector<std::future<Opened>> opening;
  const auto inTurn = [](auto open) {
    std::promise<Opened> opened;
    try {
      opened.set_value(open());
    } catch (...) {
      opened.set_exception(std::current_exception());
    }
    return opened.get_future();
  };
  for (const auto& camera : rig) {
    const auto& name = camera.calibration.name;
    // Every camera has a source: a config without one is refused.
    std::visit(
        Overloaded{
            [&](const capture::FileSourceSettings& file) {
              opening.push_back(std::async(std::launch::async, [&file, &config, &name,
                                                                replayStart] {
                auto settings = file;
                settings.pacing = config.capture.pacing;
                std::string origin = settings.path.string();
                return Opened{std::make_unique<capture::FileSource>(name, settings, replayStart),
                              std::move(origin)};
              }));
            },
            [&](const capture::PreloadSettings& preload) {
              opening.push_back(inTurn([&] {
                auto preloaded = openPreloaded(config, name, preload, preloadedBytes, replayStart);
                preloadedBytes.emplace_back(name, preloaded->bytes());
                std::string origin =
                    fmt::format("{} (preloaded as {}, {:.1f} MiB)", preload.file.path.string(),
                                capture::toString(preload.format),
                                static_cast<double>(preloaded->bytes()) / kBytesPerMib);
                return Opened{std::move(preloaded), std::move(origin)};
              }));
            },
            [&](const capture::V4l2Settings& device) {
              opening.push_back(std::async(std::launch::async, [&device, &name] {
                auto opened = std::make_unique<capture::V4l2Source>(name, device);
                std::string origin = fmt::format("{} ({})", device.device.string(),
                                                 capture::toString(opened->format()));
                return Opened{std::move(opened), std::move(origin)};
              }));
            },
            [&](const capture::LibcameraSettings& libcamera) {
              opening.push_back(inTurn([&] {
                return Opened{std::make_unique<capture::LibcameraSource>(name, libcamera),
                              fmt::format("libcamera {}", libcamera.camera)};
              }));
            },
        },
        *camera.source);
  }
  // In the config's order: the first camera that fails is the one named, as when they opened in
  // turn; the others' threads are waited for (their futures' destruction) and what they opened
  // is closed.
  std::vector<std::unique_ptr<capture::CameraStream>> cameras;
  for (std::size_t c = 0; c < rig.size(); ++c) {
    const auto& camera = rig[c];
    const auto& name = camera.calibration.name;
    auto [source, origin] = opening[c].get();
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
