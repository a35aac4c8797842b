#pragma once
// The H.264 encoder's settings and keys, one rule for every output type that encodes (video,
// network, rtsp, recording): which encoder, its quality, x264's preset, the pixel format. A type's
// settings hold them as `h264`.

#include <string>
#include <vector>

#include "daemon/config/config_keys.hpp"
#include "daemon/config/output_type.hpp"
#include "render/outputs/video_encoder.hpp"

namespace surroundd::daemon {

struct H264Settings {
  std::string encoder = "auto";  // auto | libx264 | an FFmpeg encoder's name
  int crf = 23;
  std::string preset = "veryfast";
  std::string pixelFormat = "yuv420p";

  bool operator==(const H264Settings&) const = default;
};

template <class Settings>
ConfigKey<Settings> crfKey() {
  return ConfigKey<Settings>::integer("crf", nested(&Settings::h264, &H264Settings::crf), 0, 51,
                                      "x264 constant rate factor");
}

// encoder, crf, preset and pixel_format, in the reference's order.
template <class Settings>
std::vector<ConfigKey<Settings>> h264Keys() {
  using Key = ConfigKey<Settings>;
  return {
      Key::text("encoder", nested(&Settings::h264, &H264Settings::encoder),
                "the H.264 encoder: auto (the first of h264_nvenc, h264_vaapi, h264_v4l2m2m that "
                "opens here, else libx264; the log says which) | libx264 | an FFmpeg encoder's "
                "name"),
      crfKey<Settings>(),
      Key::choice("preset", nested(&Settings::h264, &H264Settings::preset),
                  {{"ultrafast", "ultrafast"},
                   {"superfast", "superfast"},
                   {"veryfast", "veryfast"},
                   {"faster", "faster"},
                   {"fast", "fast"},
                   {"medium", "medium"}},
                  "x264 speed preset"),
      Key::choice("pixel_format", nested(&Settings::h264, &H264Settings::pixelFormat),
                  {{"yuv420p", "yuv420p"}, {"yuv444p", "yuv444p"}}, "the encoded pixel format"),
  };
}

// An encoder this FFmpeg has, and H.264 (whether its device is there shows only when it opens).
void checkEncoder(YamlObject& item, const H264Settings& h264);
// The encoder's settings from these and the stream's size and rate (no path or URL).
render::VideoEncoderSettings encoderSettings(const H264Settings& h264,
                                             const OutputContext& context);

}  // namespace surroundd::daemon
