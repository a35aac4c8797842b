#include "daemon/config/camera_source_yaml.hpp"

#include <algorithm>
#include <filesystem>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "capture/sequence_pattern.hpp"
#include "common/build_info.hpp"
#include "common/overloaded.hpp"

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

// A file that is there: a video, a picture, or a sequence whose first frame is.
void checkFile(YamlObject& source, const std::filesystem::path& path) {
  std::error_code ec;
  const capture::FileNameKind kind = capture::classifyFileName(path.string());
  if (kind == capture::FileNameKind::kTooWide) {
    source.error("file", fmt::format("expected an image sequence pattern with %d or %0Nd (N up to "
                                     "{}), got '{}' (its number is wider than that)",
                                     capture::kMaxSequenceDigits, path.string()));
  } else if (kind == capture::FileNameKind::kSequence) {
    if (!sequenceExists(path)) {
      source.error(
          "file",
          fmt::format("expected an image sequence, got '{}' (its first frame does not exist)",
                      path.string()));
    }
  } else if (!std::filesystem::is_regular_file(path, ec)) {
    source.error(
        "file",
        fmt::format("expected an existing video file or picture, got '{}' ({})", path.string(),
                    std::filesystem::exists(path, ec) ? "not a regular file" : "no such file"));
  }
}

// A recording or picture sequence, its path relative to the file: decoded as it plays, or
// preloaded in the pixel format `format` names.
CameraSource readFileSource(YamlObject& source) {
  capture::FileSourceSettings settings;
  const auto path = source.outputPath("file");
  // A still picture is a camera only if it repeats; a video or a sequence plays once by default.
  settings.loop = source.boolean("loop", path && capture::isStillPicturePath(*path));
  settings.sequenceFps =
      source.number("sequence_fps", 30.0, {0.0, 1000.0, true, "frames per second"});
  const std::optional<capture::PixelLayout> preload = readPreload(source);
  source.finish();
  if (path) {
    settings.path = *path;
    checkFile(source, *path);
  }
  if (!preload) return settings;
  capture::PreloadSettings preloaded;
  preloaded.file = std::move(settings);
  preloaded.format = *preload;
  return preloaded;
}

// A live camera's device path is taken as written (a /dev path, not relative to the file).
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

// A source's `format` word.
template <class Format, std::size_t N>
std::string wordOf(const std::array<std::pair<std::string_view, Format>, N>& words, Format format) {
  const auto found = std::ranges::find(words, format, &std::pair<std::string_view, Format>::second);
  return found == words.end() ? std::string("?") : std::string(found->first);
}

void writeFile(YAML::Emitter& out, const capture::FileSourceSettings& file,
               const std::filesystem::path& folder) {
  const bool inside = file.path.parent_path() == folder;
  out << YAML::Key << "file" << YAML::Value << (inside ? file.path.filename() : file.path).string();
  if (file.loop || capture::isStillPicturePath(file.path)) {
    out << YAML::Key << "loop" << YAML::Value << file.loop;
  }
  if (file.sequenceFps != capture::FileSourceSettings{}.sequenceFps) {
    out << YAML::Key << "sequence_fps" << YAML::Value << file.sequenceFps;
  }
}

// What a live camera's keys share.
template <class Settings>
void writeStream(YAML::Emitter& out, const Settings& live) {
  out << YAML::Key << "fps" << YAML::Value << live.fps;
  out << YAML::Key << "buffers" << YAML::Value << live.buffers;
  out << YAML::Key << "timeout_ms" << YAML::Value << live.timeout.count();
}

// The file of a replayed source, const as the source is.
template <class Source>
auto fileOf(Source& source) -> decltype(&std::get<capture::FileSourceSettings>(source)) {
  if (auto* file = std::get_if<capture::FileSourceSettings>(&source)) return file;
  if (auto* preloaded = std::get_if<capture::PreloadSettings>(&source)) return &preloaded->file;
  return nullptr;
}

}  // namespace

bool isLive(const CameraSource& source) {
  return std::holds_alternative<capture::V4l2Settings>(source) ||
         std::holds_alternative<capture::LibcameraSettings>(source);
}

const capture::FileSourceSettings* replayedFile(const CameraSource& source) {
  return fileOf(source);
}

capture::FileSourceSettings* replayedFile(CameraSource& source) { return fileOf(source); }

std::optional<capture::PixelLayout> preloadFormat(const CameraSource& source) {
  if (const auto* preloaded = std::get_if<capture::PreloadSettings>(&source)) {
    return preloaded->format;
  }
  return std::nullopt;
}

CameraSource withPreload(const CameraSource& source, std::optional<capture::PixelLayout> format) {
  const capture::FileSourceSettings* file = replayedFile(source);
  if (file == nullptr) return source;
  if (!format) return *file;
  capture::PreloadSettings preloaded;
  preloaded.file = *file;
  preloaded.format = *format;
  return preloaded;
}

CameraSource readCameraSource(YamlObject& source, cv::Size size) {
  if (source.has("device")) {
    capture::V4l2Settings device = readV4l2Source(source);
    device.size = size;
    return device;
  }
  if (source.has("libcamera")) {
    capture::LibcameraSettings camera = readLibcameraSource(source);
    camera.size = size;
    return camera;
  }
  return readFileSource(source);
}

void writeCameraSource(YAML::Emitter& out, const CameraSource& source,
                       const std::filesystem::path& folder) {
  out << YAML::Flow << YAML::BeginMap;
  std::visit(Overloaded{
                 [&](const capture::FileSourceSettings& file) { writeFile(out, file, folder); },
                 [&](const capture::PreloadSettings& preloaded) {
                   writeFile(out, preloaded.file, folder);
                   out << YAML::Key << "preload" << YAML::Value << true;
                   out << YAML::Key << "format" << YAML::Value
                       << wordOf(kPreloadFormats, preloaded.format);
                 },
                 [&](const capture::V4l2Settings& device) {
                   out << YAML::Key << "device" << YAML::Value << device.device.string();
                   out << YAML::Key << "format" << YAML::Value
                       << wordOf(kV4l2Formats, device.format);
                   writeStream(out, device);
                   if (!device.controls.empty()) {
                     out << YAML::Key << "controls" << YAML::Value << YAML::BeginMap;
                     for (const auto& control : device.controls) {
                       out << YAML::Key << control.name << YAML::Value << control.value;
                     }
                     out << YAML::EndMap;
                   }
                 },
                 [&](const capture::LibcameraSettings& camera) {
                   out << YAML::Key << "libcamera" << YAML::Value << camera.camera;
                   writeStream(out, camera);
                 },
             },
             source);
  out << YAML::EndMap;
}

}  // namespace surroundd::daemon
