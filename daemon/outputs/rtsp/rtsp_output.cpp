// Encoding runs on a thread of its own behind a queue, and only while a viewer watches.
#include "daemon/outputs/rtsp/rtsp_output.hpp"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "render/outputs/rtsp_stream_sink.hpp"

namespace surroundd::daemon {
namespace {

// The newest picture wins: a viewer watches live.
constexpr std::size_t kEncoderQueue = 2;

// What the stream is called when the config does not say: what it shows.
std::string streamName(const OutputConfig& output) {
  const std::string& name = settingsOf<RtspOutputSettings>(output).name;
  if (!name.empty()) return name;
  switch (output.stream) {
    case OutputStream::kMosaic:
      return "mosaic";
    case OutputStream::kPanorama:
      return "panorama";
    case OutputStream::kSurround:
      return "surround";
  }
  return "surround";
}

// One path segment a player's URL needs no escaping for.
void checkRtsp(YamlObject& item, const OutputConfig& /*output*/,
               const RtspOutputSettings& settings) {
  checkEncoder(item, settings.h264);
  requireCredentialsBeyondThisMachine(item, settings.server);
  const bool plain = std::ranges::all_of(settings.name, [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '_' || c == '.';
  });
  if (!plain) {
    item.error("name",
               fmt::format("expected letters, digits, '-', '_' and '.', got '{}'", settings.name));
  }
}

std::unique_ptr<render::FrameSink> openRtsp(const OutputConfig& output,
                                            const OutputContext& context) {
  const auto& own = settingsOf<RtspOutputSettings>(output);
  render::RtspStreamSettings settings;
  settings.address = own.server.address;
  settings.port = own.server.port;
  settings.name = streamName(output);
  settings.video = encoderSettings(own.h264, context);
  settings.credentials = own.server.credentials;
  auto sink = std::make_unique<render::RtspStreamSink>(std::move(settings));
  spdlog::info("RTSP stream: {}", sink->url());
  return queuedSink(std::move(sink), context, kEncoderQueue);
}

}  // namespace

OutputType rtspOutputType() {
  OutputType type;
  type.name = "rtsp";
  using Key = ConfigKey<RtspOutputSettings>;
  std::vector<Key> keys{
      listenKey<RtspOutputSettings>(),
      Key::text("name", &RtspOutputSettings::name,
                "the stream's name in its address, rtsp://HOST:PORT/NAME", Shown::kExample),
  };
  for (auto& key : h264Keys<RtspOutputSettings>()) keys.push_back(std::move(key));
  keys.push_back(passwordFileKey<RtspOutputSettings>());
  readsSettings<RtspOutputSettings>(type, ConfigKeys(std::move(keys)), checkRtsp);
  // One server per output.
  type.conflict = [](const OutputConfig& earlier, const OutputConfig& output) {
    return sharesPort(settingsOf<RtspOutputSettings>(earlier).server,
                      settingsOf<RtspOutputSettings>(output).server);
  };
  type.openPictureSink = openRtsp;
  return type;
}

}  // namespace surroundd::daemon
