#pragma once
// Command line of `surround-calibrate guide`: the camera to read (a V4L2 device, or a file
// replayed at its own pace), where to serve the page, and the lens options of
// `surround-calibrate intrinsics` (board, model, --out, limits, --update-rig).

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include <opencv2/core.hpp>

#include "render/outputs/credentials.hpp"
#include "tools/calibrate/intrinsics/intrinsics_options.hpp"

namespace surroundd::calibrate {

struct GuideOptions {
  IntrinsicsOptions lens;  // everything but the picture folder
  // One of the two: a live camera, or a video / picture sequence ("frame_%04d.png") / picture.
  std::optional<std::filesystem::path> device;
  std::optional<std::filesystem::path> file;
  cv::Size size{1280, 720};  // --device: the size to ask for
  double fps = 30;           // --device: the rate to ask for; --file: a picture sequence's rate
  bool loop = false;         // --file: start again at its end
  std::string address = "127.0.0.1";               // IPv4 to listen on
  int port = 8080;                                 // 0: any free port (printed)
  std::optional<render::Credentials> credentials;  // --password-file: who may see the page
};

extern const std::string_view kGuideUsage;

// `arguments` follow the subcommand. Throws UsageError.
GuideOptions parseGuide(std::span<const std::string_view> arguments);

}  // namespace surroundd::calibrate
