// The `http` output: MJPEG over HTTP with a live page (render::HttpStreamSink); JPEG encoding runs
// on a thread of its own behind a queue, and the page's view requests and status go through
// FrameSink::page().
#include <charconv>

#include <arpa/inet.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "daemon/built_in_outputs.hpp"
#include "render/outputs/http_stream_sink.hpp"

namespace surroundd::daemon {
namespace {

// A page shows the newest picture: one may wait while the one before is encoded.
constexpr std::size_t kPageQueue = 1;

// "ADDRESS:PORT" of an IPv4 address; port 0 picks a free one.
void readListen(YamlObject& item, OutputConfig& o) {
  const std::string listen =
      item.string("listen", fmt::format("{}:{}", o.listenAddress, o.listenPort));
  const auto colon = listen.rfind(':');
  int port = -1;
  if (colon != std::string::npos) {
    const std::string_view digits = std::string_view(listen).substr(colon + 1);
    const auto [end, failed] = std::from_chars(digits.data(), digits.data() + digits.size(), port);
    if (failed != std::errc() || end != digits.data() + digits.size()) port = -1;
  }
  in_addr address{};
  if (colon == std::string::npos || port < 0 || port > 65535 ||
      inet_pton(AF_INET, listen.substr(0, colon).c_str(), &address) != 1) {
    item.error("listen",
               fmt::format("expected IPv4-ADDRESS:PORT (e.g. 127.0.0.1:8080), got '{}'", listen));
    return;
  }
  o.listenAddress = listen.substr(0, colon);
  o.listenPort = port;
}

bool sameListen(const OutputConfig& a, const OutputConfig& b) {
  return a.listenAddress == b.listenAddress && a.listenPort == b.listenPort;
}

// Two servers cannot listen on one port of one address (0.0.0.0 is every address).
std::optional<OutputConflict> sharesPort(const OutputConfig& earlier, const OutputConfig& output) {
  const bool sameAddress = earlier.listenAddress == output.listenAddress ||
                           earlier.listenAddress == "0.0.0.0" || output.listenAddress == "0.0.0.0";
  if (output.listenPort == 0 || output.listenPort != earlier.listenPort || !sameAddress) {
    return std::nullopt;
  }
  return OutputConflict{"listen", fmt::format("listens on port {} already", output.listenPort)};
}

// For a surround stream the page offers every view, the output's own first.
std::unique_ptr<render::FrameSink> openHttp(const OutputConfig& output,
                                            const OutputContext& context) {
  render::HttpStreamSettings settings;
  settings.address = output.listenAddress;
  settings.port = output.listenPort;
  settings.jpegQuality = output.jpegQuality;
  settings.allowedHosts = output.allowedHosts;
  if (output.stream == OutputStream::kSurround) {
    for (const auto& [name, kind] : render::kViewNames) settings.views.emplace_back(name);
    settings.initialView = toString(output.view.value_or(ViewKind::kOrbit));
  }
  auto sink = std::make_unique<render::HttpStreamSink>(std::move(settings));
  spdlog::info("HTTP stream: http://{}:{}/", output.listenAddress, sink->port());
  return queuedSink(std::move(sink), context, kPageQueue);
}

}  // namespace

OutputType httpOutputType() {
  OutputType type;
  type.name = "http";
  using Key = ConfigKey<OutputConfig>;
  type.keys = {
      Key::custom("listen", "the address and port it listens on", readListen, sameListen),
      Key::integer("quality", &OutputConfig::jpegQuality, 1, 100, "JPEG quality"),
      Key::names("allowed_hosts", &OutputConfig::allowedHosts, 0, 32, "host names it answers to"),
  };
  type.conflict = sharesPort;
  type.openPictureSink = openHttp;
  return type;
}

}  // namespace surroundd::daemon
