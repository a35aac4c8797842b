// The `http` output: MJPEG over HTTP with a live page (render::HttpStreamSink); JPEG encoding runs
// on a thread of its own behind a queue, and the page's view requests and status go through
// FrameSink::page().
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "daemon/outputs/built_in_outputs.hpp"
#include "render/outputs/http_stream_sink.hpp"

namespace surroundd::daemon {
namespace {

// A page shows the newest picture: one may wait while the one before is encoded.
constexpr std::size_t kPageQueue = 1;

// For a surround stream the page offers every view, the output's own first.
std::unique_ptr<render::FrameSink> openHttp(const OutputConfig& output,
                                            const OutputContext& context) {
  render::HttpStreamSettings settings;
  settings.address = output.listenAddress;
  settings.port = output.listenPort;
  settings.jpegQuality = output.jpegQuality;
  settings.allowedHosts = output.allowedHosts;
  settings.credentials = output.credentials;
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
      listenKey(8080),
      Key::integer("quality", &OutputConfig::jpegQuality, 1, 100, "JPEG quality"),
      Key::names("allowed_hosts", &OutputConfig::allowedHosts, 0, 32, "host names it answers to"),
      passwordFileKey(),
  };
  type.readSettings = requireCredentialsBeyondThisMachine;
  type.conflict = sharesPort;
  type.openPictureSink = openHttp;
  return type;
}

}  // namespace surroundd::daemon
