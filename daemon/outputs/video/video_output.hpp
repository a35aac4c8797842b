#pragma once
// The `video` and `network` output types: H.264 through one render::VideoSink, into a file
// (segmented or not) or as MPEG-TS over UDP.

#include <string>

#include "daemon/config/output_type.hpp"
#include "daemon/outputs/h264_settings.hpp"

namespace surroundd::daemon {

struct VideoOutputSettings {
  H264Settings h264;
  double segmentS = 0.0;  // a new file every this many seconds of stream time; 0: one file
  // How many of its files (runs, segments) to keep, and how many MB they may hold; 0: all.
  int keepLast = 0;
  double maxMb = 0;

  bool operator==(const VideoOutputSettings&) const = default;
};

struct NetworkOutputSettings {
  std::string url;  // udp://HOST:PORT (MPEG-TS)
  H264Settings h264;

  bool operator==(const NetworkOutputSettings&) const = default;
};

OutputType videoOutputType();
OutputType networkOutputType();

}  // namespace surroundd::daemon
