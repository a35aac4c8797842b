#pragma once
// The `rtsp` output type: H.264 served over RTSP at rtsp://HOST:PORT/NAME
// (render::RtspStreamSink).

#include <string>

#include "daemon/config/output_type.hpp"
#include "daemon/outputs/h264_settings.hpp"
#include "daemon/outputs/server_settings.hpp"

namespace surroundd::daemon {

struct RtspOutputSettings {
  ServerSettings server{.port = 8554, .credentials = {}};  // the conventional RTSP port
  std::string name;  // empty: what it shows (surround, panorama, mosaic)
  H264Settings h264;

  bool operator==(const RtspOutputSettings&) const = default;
};

OutputType rtspOutputType();

}  // namespace surroundd::daemon
