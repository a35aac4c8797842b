// JPEG encoding runs on a thread of its own behind a queue, and the page's view requests and
// status go through FrameSink::page().
#include "daemon/outputs/http/http_output.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "render/outputs/http_stream_sink.hpp"

namespace surroundd::daemon {
namespace {

// A page shows the newest picture: one may wait while the one before is encoded.
constexpr std::size_t kPageQueue = 1;

// For a surround stream the page offers every view, the output's own first.
std::unique_ptr<render::FrameSink> openHttp(const OutputConfig& output,
                                            const OutputContext& context) {
  const auto& own = settingsOf<HttpOutputSettings>(output);
  render::HttpStreamSettings settings;
  settings.address = own.server.address;
  settings.port = own.server.port;
  settings.jpegQuality = own.jpegQuality;
  settings.allowedHosts = own.allowedHosts;
  settings.credentials = own.server.credentials;
  if (output.stream == OutputStream::kSurround) {
    for (const auto& [name, kind] : render::kViewNames) settings.views.emplace_back(name);
    settings.initialView = toString(output.view.value_or(ViewKind::kOrbit));
  }
  auto sink = std::make_unique<render::HttpStreamSink>(std::move(settings));
  spdlog::info("HTTP stream: http://{}:{}/", own.server.address, sink->port());
  return queuedSink(std::move(sink), context, kPageQueue);
}

}  // namespace

OutputType httpOutputType() {
  OutputType type;
  type.name = "http";
  using Key = ConfigKey<HttpOutputSettings>;
  readsSettings<HttpOutputSettings>(
      type,
      {
          listenKey<HttpOutputSettings>(),
          Key::integer("quality", &HttpOutputSettings::jpegQuality, 1, 100, "JPEG quality"),
          Key::names("allowed_hosts", &HttpOutputSettings::allowedHosts, 0, 32,
                     "host names it answers to"),
          passwordFileKey<HttpOutputSettings>(),
      },
      [](YamlObject& item, const OutputConfig&, const HttpOutputSettings& settings) {
        requireCredentialsBeyondThisMachine(item, settings.server);
      });
  type.conflict = [](const OutputConfig& earlier, const OutputConfig& output) {
    return sharesPort(settingsOf<HttpOutputSettings>(earlier).server,
                      settingsOf<HttpOutputSettings>(output).server);
  };
  type.openPictureSink = openHttp;
  return type;
}

}  // namespace surroundd::daemon
