#include "daemon/config/panorama_setup.hpp"

#include <chrono>
#include <cstdlib>
#include <numbers>

#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "daemon/config/rig_yaml.hpp"
#include "daemon/config/vehicle_yaml.hpp"
#include "processing/stitch/panorama_lut_cache.hpp"

namespace surroundd::daemon {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180;

// Set and non-empty, or nullptr.
const char* environment(const char* name) {
  // Read once at start-up; surroundd never changes its environment.
  const char* value = std::getenv(name);  // NOLINT(concurrency-mt-unsafe)
  return value != nullptr && *value != '\0' ? value : nullptr;
}

}  // namespace

cv::Mat bodyMaskOf(const Config& config, std::size_t index, WorkPool& pool) {
  const RigCamera& camera = config.cameras[index];
  const cv::Size size = camera.calibration.intrinsics.imageSize;
  const bool replace = camera.bodyMask && camera.bodyMask->mode == BodyMaskConfig::Mode::kReplace;
  cv::Mat mask;
  if (config.vehicle && config.vehicle->bodyMasks && !replace) {
    mask = processing::computeBodyMask(config.vehicle->body(), camera.calibration, pool);
  } else {
    mask = cv::Mat(size, CV_8U, cv::Scalar(0));
  }
  if (camera.bodyMask) {
    const auto& own = *camera.bodyMask;
    if (!own.file.empty()) {
      const cv::Mat picture = bodyMaskPicture(own.file);
      if (picture.empty() || picture.size() != size) {
        throw std::runtime_error(fmt::format(
            "{}: camera '{}': body_mask.file {}: expected a {}x{} picture (white = body), got {}",
            config.file.string(), camera.calibration.name, own.file.string(), size.width,
            size.height,
            picture.empty() ? std::string("none that can be read")
                            : fmt::format("{}x{}", picture.cols, picture.rows)));
      }
      mask |= picture > 127;
    }
    // One at a time: where two overlap, both are body (fillPoly of several would leave a hole).
    for (const auto& polygon : own.polygons) {
      std::vector<cv::Point> corners;
      corners.reserve(polygon.size());
      for (const auto& [u, v] : polygon) {
        corners.emplace_back(static_cast<int>(std::lround(u)), static_cast<int>(std::lround(v)));
      }
      cv::fillPoly(mask, std::vector{corners}, cv::Scalar(255));
    }
  }
  return cv::countNonZero(mask) == 0 ? cv::Mat() : mask;
}

processing::Rig rigOf(const Config& config, WorkPool& pool) {
  processing::Rig rig;
  for (std::size_t c = 0; c < config.cameras.size(); ++c) {
    rig.cameras.push_back(config.cameras[c].calibration);
    auto& camera = rig.cameras.back();
    camera.bodyMask = bodyMaskOf(config, c, pool);
    if (!camera.bodyMask.empty()) {
      spdlog::info(
          "camera '{}': {:.1f} % of the picture sees the vehicle's body, left out of the "
          "panorama and colour correction",
          camera.name,
          100.0 * cv::countNonZero(camera.bodyMask) / static_cast<double>(camera.bodyMask.total()));
    }
  }
  return rig;
}

processing::PanoramaSettings panoramaSettings(const Config& config) {
  processing::PanoramaSettings settings;
  const auto& p = config.panorama;
  settings.geometry.size = {p.widthPx, p.heightPx};
  settings.geometry.elevationTopRad = p.elevationTopDeg * kDegToRad;
  settings.geometry.elevationBottomRad = p.elevationBottomDeg * kDegToRad;
  double height = 0;
  for (const auto& camera : config.cameras) height += camera.calibration.pose.position[2];
  settings.geometry.centre = {0, 0, height / static_cast<double>(config.cameras.size())};
  settings.projection = p.projection;
  settings.featherRad = p.featherDeg * kDegToRad;
  settings.bowl = {config.mesh.bowlFloorRadiusM, config.mesh.bowlRadiusM, config.mesh.bowlHeightM};
  return settings;
}

processing::MeshSettings meshSettings(const Config& config) {
  return {config.mesh.model,         config.mesh.flatRadiusM,
          config.mesh.sphereRadiusM, panoramaSettings(config).bowl,
          config.mesh.rings,         config.mesh.segments};
}

std::filesystem::path lutCacheDir(const Config& config) {
  if (!config.panorama.cacheDir.empty()) return config.panorama.cacheDir;
  if (const char* state = environment("STATE_DIRECTORY")) return state;
  if (const char* cache = environment("XDG_CACHE_HOME")) {
    return std::filesystem::path(cache) / "surroundd";
  }
  if (const char* home = environment("HOME"))
    return std::filesystem::path(home) / ".cache" / "surroundd";
  return std::filesystem::temp_directory_path() / "surroundd";
}

namespace {

processing::PanoramaLut loadOrBuildLut(const Config& config, const processing::Rig& rig,
                                       WorkPool& pool) {
  const processing::PanoramaSettings settings = panoramaSettings(config);
  const std::string key = processing::panoramaLutKey(rig, settings);
  const processing::PanoramaLutCache cache(lutCacheDir(config));
  auto lookup = cache.load(key, settings.geometry.size);
  if (lookup.lut) {
    spdlog::info("panorama LUT {}x{}: loaded {}", settings.geometry.size.width,
                 settings.geometry.size.height, cache.fileFor(key).string());
    return std::move(*lookup.lut);
  }
  if (lookup.problem != "absent")
    spdlog::warn("panorama LUT cache: {}; rebuilding", lookup.problem);
  spdlog::info("panorama LUT {}x{} ({} projection): building", settings.geometry.size.width,
               settings.geometry.size.height,
               settings.projection == processing::PanoramaProjection::kBowl ? "bowl" : "sphere");
  const auto start = std::chrono::steady_clock::now();
  processing::PanoramaLut lut;
  try {
    lut = processing::buildPanoramaLut(rig, settings, pool, [](double done) {
      spdlog::info("panorama LUT: {:.0f} %", done * 100);
    });
  } catch (const processing::RigError& e) {
    throw std::runtime_error(fmt::format("{}: rig: {}", config.file.string(), e.what()));
  }
  spdlog::info("panorama LUT built in {:.2f} s ({} blend taps)",
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
               lut.blendTaps.size());
  try {
    cache.store(key, lut);
    spdlog::info("panorama LUT stored in {}", cache.fileFor(key).string());
  } catch (const std::exception& e) {
    spdlog::warn("panorama LUT not cached: {}", e.what());
  }
  return lut;
}

// A camera the LUT takes nothing from: its body mask hides all it would show (buildPanoramaLut()
// refuses a camera that sees nothing for any other reason).
void warnOfHiddenCameras(const processing::Rig& rig, const processing::PanoramaLut& lut) {
  for (const std::size_t c : lut.camerasWithoutTaps()) {
    const auto& camera = rig.cameras[c];
    const double masked = 100.0 * cv::countNonZero(camera.bodyMask) /
                          static_cast<double>(std::max<std::size_t>(camera.bodyMask.total(), 1));
    spdlog::warn(
        "camera '{}' contributes nothing to the panorama: its body mask ({:.0f} % of its picture) "
        "hides all it would show; the panorama is made from the other cameras. Check vehicle: (a "
        "camera inside the body's box sees only the body: give the footprint instead, or find the "
        "body with surround-calibrate mask --from a recorded drive) and the camera's body_mask:",
        camera.name, masked);
  }
}

}  // namespace

processing::PanoramaLut obtainPanoramaLut(const Config& config, const processing::Rig& rig,
                                          WorkPool& pool) {
  processing::PanoramaLut lut = loadOrBuildLut(config, rig, pool);
  warnOfHiddenCameras(rig, lut);
  return lut;
}

}  // namespace surroundd::daemon
