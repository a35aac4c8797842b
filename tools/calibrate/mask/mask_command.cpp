#include "tools/calibrate/mask/mask_command.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include "capture/file_source.hpp"
#include "common/work_pool.hpp"
#include "daemon/config/config.hpp"
#include "daemon/config/panorama_setup.hpp"
#include "tools/calibrate/calibration_output.hpp"
#include "tools/calibrate/mask/drive_mask_command.hpp"
#include "tools/calibrate/mask/mask_overlay.hpp"

namespace surroundd::calibrate {
namespace {

// The camera's first frame. A live camera is not opened: a running surroundd may hold the device.
cv::Mat firstPicture(const daemon::RigCamera& camera) {
  const cv::Size size = camera.calibration.intrinsics.imageSize;
  // A live camera's stand-in picture: dark, so that the tint and the outline still show.
  if (!camera.replayedFile()) return {size, CV_8UC3, cv::Scalar::all(64)};
  const std::string& name = camera.calibration.name;
  auto settings = *camera.replayedFile();
  settings.pacing = capture::Pacing::kAsFastAsPossible;  // no wait for the first frame's time
  try {
    capture::FileSource source(name, settings);
    if (source.frameSize() != size) {
      throw UsageError(
          fmt::format("camera '{}': {} has {}x{} frames but the lens is calibrated for {}x{}", name,
                      settings.path.string(), source.frameSize().width, source.frameSize().height,
                      size.width, size.height));
    }
    capture::Frame frame;
    frame.image.create(size, CV_8UC3);
    if (source.read(frame) != capture::ReadStatus::kFrame) {
      throw UsageError(fmt::format("camera '{}': cannot read a frame of {}: {}", name,
                                   settings.path.string(), source.lastError()));
    }
    return frame.image;
  } catch (const capture::CaptureError& error) {
    throw UsageError(error.what());
  }
}

// Where bodyMaskOf's mask comes from, in the config's words.
std::string maskOrigin(const daemon::Config& config, const daemon::RigCamera& camera) {
  const auto& own = camera.bodyMask;
  const bool replace = own && own->mode == daemon::BodyMaskConfig::Mode::kReplace;
  std::vector<std::string> parts;
  if (config.vehicle && config.vehicle->bodyMasks && !replace) {
    parts.emplace_back("computed from vehicle:");
  }
  if (own && !own->file.empty()) parts.push_back("file " + own->file.filename().string());
  if (own && !own->polygons.empty()) parts.emplace_back("polygon");
  if (parts.empty()) {
    return config.vehicle ? "nothing: vehicle.body_masks is false" : "nothing: no vehicle";
  }
  std::string joined = parts.front();
  for (std::size_t i = 1; i < parts.size(); ++i) joined += " + " + parts[i];
  return joined;
}

// `{file: PATH, mode: replace}`, quoted where the path needs it.
std::string replaceMaskYaml(const std::filesystem::path& file) {
  YAML::Emitter out;
  out << YAML::Flow << YAML::BeginMap << YAML::Key << "file" << YAML::Value << file.string()
      << YAML::Key << "mode" << YAML::Value << "replace" << YAML::EndMap;
  return out.c_str();
}

}  // namespace

void runMask(const MaskOptions& options, std::ostream& log) {
  if (!options.from.empty()) {
    runDriveMask(options, log);
    return;
  }
  const daemon::Config config = daemon::loadConfig(options.config);
  std::vector<std::size_t> chosen;
  std::string names;
  for (std::size_t c = 0; c < config.cameras.size(); ++c) {
    const std::string& name = config.cameras[c].calibration.name;
    names += (names.empty() ? "" : ", ") + name;
    if (options.camera.empty() || name == options.camera) chosen.push_back(c);
  }
  if (chosen.empty()) {
    throw UsageError(fmt::format("--camera: {} has no camera '{}' (its cameras: {})",
                                 options.config.string(), options.camera, names));
  }
  const bool anyOwnMask = std::ranges::any_of(
      config.cameras, [](const daemon::RigCamera& camera) { return camera.bodyMask.has_value(); });
  if (!config.vehicle && !anyOwnMask) {
    log << fmt::format(
        "{}: no vehicle is configured (no vehicle: block, no camera with a body_mask:), so "
        "nothing is masked; the pictures show 0 %. Add vehicle: {{length_m, width_m, height_m}} "
        "for masks computed from the car's body.\n",
        options.config.string());
  }

  WorkPool pool;
  std::vector<std::pair<std::string, std::filesystem::path>> bodyFiles;
  for (const std::size_t c : chosen) {
    const daemon::RigCamera& camera = config.cameras[c];
    const std::string& name = camera.calibration.name;
    const cv::Mat picture = firstPicture(camera);
    cv::Mat mask;
    try {
      mask = daemon::bodyMaskOf(config, c, pool);
    } catch (const std::runtime_error& error) {
      throw UsageError(error.what());  // a body_mask.file that does not fit the lens
    }
    if (mask.empty()) mask = cv::Mat::zeros(picture.size(), CV_8U);
    const double share = 100.0 * cv::countNonZero(mask) / static_cast<double>(mask.total());
    const std::string origin = maskOrigin(config, camera);
    std::vector<std::string> label{name, fmt::format("{:.1f} % of the picture masked", share),
                                   origin};
    if (camera.live()) label.emplace_back("live camera: grey, no frame read");

    const auto overlayFile = options.out / (name + "-mask-overlay.png");
    const auto bodyFile = options.out / (name + "-body.png");
    writePng(bodyFile, mask);
    writePng(overlayFile, maskOverlay(picture, mask, label));
    bodyFiles.emplace_back(name, bodyFile);
    log << fmt::format("{}: {:.1f} % masked ({}){}: {}, {}\n", name, share, origin,
                       camera.live() ? ", live camera: drawn on grey" : "", overlayFile.string(),
                       bodyFile.string());
  }

  log << "\nTo use the masks after editing them (white = body), give each camera in the rig:\n";
  for (const auto& [name, file] : bodyFiles) {
    log << fmt::format("  - name: {}\n    body_mask: {}\n", name,
                       replaceMaskYaml(std::filesystem::absolute(file).lexically_normal()));
  }
}

}  // namespace surroundd::calibrate
