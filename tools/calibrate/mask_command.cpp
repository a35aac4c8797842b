#include "tools/calibrate/mask_command.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include "capture/file_source.hpp"
#include "common/work_pool.hpp"
#include "daemon/config.hpp"
#include "daemon/panorama_setup.hpp"
#include "tools/calibrate/calibration_output.hpp"

namespace surroundd::calibrate {
namespace {

// BGR. Yellow outlines stand out on the red tint and on most road scenes.
const cv::Scalar kTint(0, 0, 255);
const cv::Scalar kOutline(0, 255, 255);
const cv::Scalar kLabelBackground(0, 0, 0);
const cv::Scalar kLabelText(255, 255, 255);
// A live camera's stand-in picture: dark, so that the tint and the outline still show.
const cv::Scalar kLiveGrey = cv::Scalar::all(64);

// The camera's first frame. A live camera is not opened: a running surroundd may hold the device.
cv::Mat firstPicture(const daemon::RigCamera& camera) {
  const cv::Size size = camera.calibration.intrinsics.imageSize;
  if (!camera.source) return {size, CV_8UC3, kLiveGrey};
  const std::string& name = camera.calibration.name;
  auto settings = *camera.source;
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
  if (own && !own->polygon.empty()) parts.emplace_back("polygon");
  if (parts.empty()) {
    return config.vehicle ? "nothing: vehicle.body_masks is false" : "nothing: no vehicle";
  }
  std::string joined = parts.front();
  for (std::size_t i = 1; i < parts.size(); ++i) joined += " + " + parts[i];
  return joined;
}

// White text on black, sized to the picture (legible from a 320-pixel test picture to a 4K one),
// in the corner where it hides the least of the mask.
void drawLabel(cv::Mat& picture, const cv::Mat& mask, const std::vector<std::string>& lines) {
  constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
  const double scale = std::clamp(picture.cols / 1280.0, 0.35, 2.0);
  const int thickness = scale < 1 ? 1 : 2;
  const int pad = static_cast<int>(std::lround(6 * scale)) + 2;
  int width = 0, textHeight = 0, descent = 0;
  for (const auto& line : lines) {
    int baseline = 0;
    const cv::Size size = cv::getTextSize(line, kFont, scale, thickness, &baseline);
    width = std::max(width, size.width);
    textHeight = std::max(textHeight, size.height);
    descent = std::max(descent, baseline);
  }
  const int lineHeight = textHeight + descent + pad;
  const int count = static_cast<int>(lines.size());
  const cv::Size box(std::min(width + 2 * pad, picture.cols),
                     std::min(lineHeight * count + pad, picture.rows));
  const int right = picture.cols - box.width, bottom = picture.rows - box.height;
  cv::Rect best;
  int bestHidden = -1;
  for (const cv::Point corner :
       {cv::Point(0, 0), cv::Point(right, 0), cv::Point(0, bottom), cv::Point(right, bottom)}) {
    const cv::Rect rect(corner, box);
    const int hidden = cv::countNonZero(mask(rect));
    if (bestHidden < 0 || hidden < bestHidden) {
      best = rect;
      bestHidden = hidden;
    }
  }
  cv::rectangle(picture, best, kLabelBackground, cv::FILLED);
  for (int i = 0; i < count; ++i) {
    cv::putText(picture, lines[static_cast<std::size_t>(i)],
                best.tl() + cv::Point(pad, pad + lineHeight * i + textHeight), kFont, scale,
                kLabelText, thickness, cv::LINE_AA);
  }
}

// The picture with the body blended half with red and its outline (holes too) drawn 2 px wide.
cv::Mat overlay(const cv::Mat& picture, const cv::Mat& mask,
                const std::vector<std::string>& label) {
  cv::Mat out = picture.clone();
  cv::Mat tinted;
  cv::addWeighted(picture, 0.5, cv::Mat(picture.size(), picture.type(), kTint), 0.5, 0, tinted);
  tinted.copyTo(out, mask);
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_LIST, cv::CHAIN_APPROX_SIMPLE);
  cv::drawContours(out, contours, -1, kOutline, 2);
  drawLabel(out, mask, label);
  return out;
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
    writePng(overlayFile, overlay(picture, mask, label));
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
