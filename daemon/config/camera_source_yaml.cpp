#include "daemon/config/camera_source_yaml.hpp"

#include <filesystem>
#include <string_view>

#include <fmt/format.h>

#include "capture/sequence_pattern.hpp"
#include "common/build_info.hpp"

namespace surroundd::daemon {
namespace {

// An image sequence pattern ("front_%06d.png") names no single file; check that its first frame
// exists, with FFmpeg's image2 default start numbers.
bool sequenceExists(const std::filesystem::path& pattern) {
  for (int index = 0; index <= 4; ++index) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(capture::sequenceFrameName(pattern.string(), index), ec)) {
      return true;
    }
  }
  return false;
}

// A file source's `preload` and `format`: the pixel format its frames are held in, or nullopt when
// it is decoded as it plays.
std::optional<capture::PixelLayout> readPreload(YamlObject& source) {
  const bool preload = source.boolean("preload", false);
  if (!preload && source.has("format")) {
    source.error("format",
                 "expected only with 'preload: true' (the pixel format preloaded frames "
                 "are held in), got it without");
    return std::nullopt;
  }
  if (!preload) return std::nullopt;
  return source.choice(
      "format", capture::PixelLayout::kYuyv,
      std::span<const std::pair<std::string_view, capture::PixelLayout>>(kPreloadFormats));
}

// A live camera delivers its own frames: `preload` belongs to a file source only.
void refusePreload(YamlObject& source, std::string_view kind) {
  if (source.has("preload")) {
    source.error("preload",
                 fmt::format("expected only in a file source (a recording preloaded into "
                             "memory), got it in a {} camera's",
                             kind));
  }
}

constexpr std::array<std::string_view, 8> kV4l2Controls{"exposure_auto",
                                                        "exposure_absolute",
                                                        "gain",
                                                        "white_balance_auto",
                                                        "white_balance_temperature",
                                                        "brightness",
                                                        "contrast",
                                                        "saturation"};

}  // namespace

capture::FileSourceSettings readFileSource(YamlObject& source,
                                           std::optional<capture::PixelLayout>& preload) {
  capture::FileSourceSettings settings;
  const auto path = source.outputPath("file");
  // A still picture is a camera only if it repeats; a video or a sequence plays once by default.
  settings.loop = source.boolean("loop", path && capture::isStillPicturePath(*path));
  settings.sequenceFps =
      source.number("sequence_fps", 30.0, {0.0, 1000.0, true, "frames per second"});
  preload = readPreload(source);
  source.finish();
  if (!path) return settings;
  settings.path = *path;
  std::error_code ec;
  const capture::FileNameKind kind = capture::classifyFileName(path->string());
  if (kind == capture::FileNameKind::kTooWide) {
    source.error("file", fmt::format("expected an image sequence pattern with %d or %0Nd (N up to "
                                     "{}), got '{}' (its number is wider than that)",
                                     capture::kMaxSequenceDigits, path->string()));
  } else if (kind == capture::FileNameKind::kSequence) {
    if (!sequenceExists(*path)) {
      source.error(
          "file",
          fmt::format("expected an image sequence, got '{}' (its first frame does not exist)",
                      path->string()));
    }
  } else if (!std::filesystem::is_regular_file(*path, ec)) {
    source.error(
        "file",
        fmt::format("expected an existing video file or picture, got '{}' ({})", path->string(),
                    std::filesystem::exists(*path, ec) ? "not a regular file" : "no such file"));
  }
  return settings;
}

capture::V4l2Settings readV4l2Source(YamlObject& source) {
  capture::V4l2Settings settings;
  settings.device = source.string("device", "");
  refusePreload(source, "V4L2");
  settings.format = source.choice(
      "format", settings.format,
      std::span<const std::pair<std::string_view, capture::V4l2Format>>(kV4l2Formats));
  settings.fps = source.number("fps", settings.fps, {1.0, 1000.0, false, "frames per second"});
  settings.buffers = source.integer("buffers", settings.buffers, 2, 32);
  settings.timeout = std::chrono::milliseconds(source.integer("timeout_ms", 500, 20, 60'000));
  if (auto controls = source.object("controls")) {
    for (const auto name : kV4l2Controls) {
      if (controls->has(name)) {
        settings.controls.push_back(
            {std::string(name), controls->integer(name, 0, -1'000'000, 1'000'000)});
      }
    }
    controls->finish();
  }
  source.finish();
  return settings;
}

capture::LibcameraSettings readLibcameraSource(YamlObject& source) {
  capture::LibcameraSettings settings;
  settings.camera = source.string("libcamera", "");
  refusePreload(source, "libcamera");
  if (!capture::libcameraAvailable()) {
    source.error("libcamera",
                 "this surroundd is built without libcamera cameras: " + howToBuildIn("LIBCAMERA"));
  }
  settings.fps = source.number("fps", settings.fps, {1.0, 1000.0, false, "frames per second"});
  settings.buffers = source.integer("buffers", settings.buffers, 2, 32);
  settings.timeout = std::chrono::milliseconds(source.integer("timeout_ms", 500, 20, 60'000));
  source.finish();
  return settings;
}

}  // namespace surroundd::daemon
