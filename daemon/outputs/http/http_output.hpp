#pragma once
// The `http` output type: MJPEG over HTTP with a live page (render::HttpStreamSink).

#include <string>
#include <vector>

#include "daemon/config/output_type.hpp"
#include "daemon/outputs/server_settings.hpp"

namespace surroundd::daemon {

struct HttpOutputSettings {
  ServerSettings server;
  int jpegQuality = 80;
  std::vector<std::string> allowedHosts;  // host names it answers to besides IPs and localhost

  bool operator==(const HttpOutputSettings&) const = default;
};

OutputType httpOutputType();

}  // namespace surroundd::daemon
