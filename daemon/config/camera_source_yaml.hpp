#pragma once
// A rig camera's `source:` in YAML (the keys: rig_yaml.hpp): a recording or picture sequence
// replayed, a V4L2 device or a libcamera camera. Errors go to the object's Diagnostics.

#include <array>
#include <optional>
#include <string_view>
#include <utility>

#include "capture/file_source.hpp"
#include "capture/libcamera_source.hpp"
#include "capture/pixel_conversion.hpp"
#include "capture/v4l2_source.hpp"
#include "daemon/config/yaml_reader.hpp"

namespace surroundd::daemon {

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

// A recording or picture sequence, its path relative to the file; `preload` is set when it is to
// be decoded once into memory in that pixel format. A source whose file is wrong is still
// returned (its error is recorded), so that the camera is not reported again as having none.
capture::FileSourceSettings readFileSource(YamlObject& source,
                                           std::optional<capture::PixelLayout>& preload);
// A live camera; its size is the lens's (set by the caller), its device path is taken as written
// (a /dev path, not relative to the file).
capture::V4l2Settings readV4l2Source(YamlObject& source);
capture::LibcameraSettings readLibcameraSource(YamlObject& source);

}  // namespace surroundd::daemon
