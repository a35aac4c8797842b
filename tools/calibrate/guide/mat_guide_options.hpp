#pragma once
// Command line of `surround-calibrate guide --mat`: the calibration mat, the rig whose mounts it
// solves (and writes on a pass), each camera's picture source, where to serve the page, and the
// limits of `surround-calibrate extrinsics --mat`.

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/mat_calibration.hpp"
#include "render/outputs/credentials.hpp"

namespace surroundd::calibrate {

struct MatGuideOptions {
  std::filesystem::path mat;  // the mat's layout (YAML)
  std::filesystem::path rig;  // lenses and the mounts assumed so far; the mounts go here on a pass
  // Each camera the mat names reads from a device of `devices`, else from its picture in `images`.
  std::optional<std::filesystem::path> images;  // NAME.png (.jpg ...) per camera
  std::vector<std::pair<std::string, std::filesystem::path>> devices;  // NAME=DEV
  std::optional<std::filesystem::path> out;  // also the mount: blocks, as extrinsics --out
  cv::Size size{1280, 720};                  // devices: the size to ask for
  double fps = 30;                           // devices: the rate to ask for
  std::string address = "127.0.0.1";
  int port = 8080;
  std::optional<render::Credentials> credentials;  // --password-file: who may see the page
  processing::MatLimits limits;
  double inlierPx = 3.0;
};

extern const std::string_view kMatGuideUsage;

// `arguments` follow the subcommand and hold --mat. Throws UsageError.
MatGuideOptions parseMatGuide(std::span<const std::string_view> arguments);

}  // namespace surroundd::calibrate
