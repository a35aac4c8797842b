#pragma once
// A rig camera's source: where its frames come from, one kind of camera each, and its `source:`
// in YAML (the keys: rig_yaml.hpp). Errors go to the object's Diagnostics.

#include <array>
#include <filesystem>
#include <optional>
#include <string_view>
#include <utility>
#include <variant>

#include <yaml-cpp/yaml.h>

#include "capture/file_source.hpp"
#include "capture/libcamera_source.hpp"
#include "capture/pixel_conversion.hpp"
#include "capture/preloaded_source.hpp"
#include "capture/v4l2_source.hpp"
#include "daemon/config/yaml_reader.hpp"

namespace surroundd::daemon {

// The settings of the capture source a camera opens: a recording or picture sequence decoded as
// it plays, or decoded once into memory and played from there as a camera's frames are held
// (capture::PreloadedSource), a V4L2 device, a libcamera camera. A new kind is its settings here,
// its reading (readCameraSource()), and its case in the visits that write it (rig_yaml.cpp) and
// open it (daemon/pipeline_ends.cpp): one it misses does not compile.
using CameraSource = std::variant<capture::FileSourceSettings, capture::PreloadSettings,
                                  capture::V4l2Settings, capture::LibcameraSettings>;

// Whether the source is a camera on the vehicle (not a file replayed).
bool isLive(const CameraSource& source);
// The file it replays (decoded as it plays or preloaded); null for a live camera.
const capture::FileSourceSettings* replayedFile(const CameraSource& source);
capture::FileSourceSettings* replayedFile(CameraSource& source);
// The pixel format a replayed file is held in; none where it is decoded as it plays, or live.
std::optional<capture::PixelLayout> preloadFormat(const CameraSource& source);
// `source`'s file decoded once into memory in `format`, or as it plays (none): a recording
// replayed either way. A live camera's source is returned as it is.
CameraSource withPreload(const CameraSource& source, std::optional<capture::PixelLayout> format);

// `source:` of a camera whose lens's picture is `size`: the kind its keys name (`device`,
// `libcamera`, else `file`). A source whose file is wrong is still returned (its error is
// recorded), so that the camera is not reported again as having none.
CameraSource readCameraSource(YamlObject& source, cv::Size size);
// The same as a flow map of `out`; a file in `folder` (the rig file's) by its name alone.
void writeCameraSource(YAML::Emitter& out, const CameraSource& source,
                       const std::filesystem::path& folder);

// The words of a source's `format`: a file source's preload format, a V4L2 device's format.
inline constexpr std::array<std::pair<std::string_view, capture::PixelLayout>, 3> kPreloadFormats{{
    {"yuyv", capture::PixelLayout::kYuyv},
    {"uyvy", capture::PixelLayout::kUyvy},
    {"nv12", capture::PixelLayout::kNv12},
}};

inline constexpr std::array<std::pair<std::string_view, capture::V4l2Format>, 5> kV4l2Formats{{
    {"auto", capture::V4l2Format::kAuto},
    {"yuyv", capture::V4l2Format::kYuyv},
    {"uyvy", capture::V4l2Format::kUyvy},
    {"nv12", capture::V4l2Format::kNv12},
    {"mjpeg", capture::V4l2Format::kMjpeg},
}};

}  // namespace surroundd::daemon
