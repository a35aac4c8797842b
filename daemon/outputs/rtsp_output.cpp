// The `rtsp` output: H.264 served over RTSP at rtsp://HOST:PORT/NAME (render::RtspStreamSink);
// encoding runs on a thread of its own behind a queue, and only while a viewer watches.
#include <algorithm>
#include <cctype>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "daemon/outputs/built_in_outputs.hpp"
#include "render/outputs/rtsp_stream_sink.hpp"

namespace surroundd::daemon {
namespace {

// The newest picture wins: a viewer watches live.
constexpr std::size_t kEncoderQueue = 2;

// The conventional RTSP port.
constexpr int kRtspPort = 8554;

// What the stream is called when the config does not say: what it shows.
std::string streamName(const OutputConfig& output) {
  if (!output.rtspName.empty()) return output.rtspName;
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
void checkRtsp(YamlObject& item, OutputConfig& o) {
  checkEncoder(item, o);
  requireCredentialsBeyondThisMachine(item, o);
  const bool plain = std::all_of(o.rtspName.begin(), o.rtspName.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '_' || c == '.';
  });
  if (!plain) {
    item.error("name",
               fmt::format("expected letters, digits, '-', '_' and '.', got '{}'", o.rtspName));
  }
}

std::unique_ptr<render::FrameSink> openRtsp(const OutputConfig& output,
                                            const OutputContext& context) {
  render::RtspStreamSettings settings;
  settings.address = output.listenAddress;
  settings.port = output.listenPort;
  settings.name = streamName(output);
  settings.video = encoderSettings(output, context);
  settings.credentials = output.credentials;
  auto sink = std::make_unique<render::RtspStreamSink>(std::move(settings));
  spdlog::info("RTSP stream: {}", sink->url());
  return queuedSink(std::move(sink), context, kEncoderQueue);
}

}  // namespace

OutputType rtspOutputType() {
  OutputType type;
  type.name = "rtsp";
  using Key = ConfigKey<OutputConfig>;
  type.keys = {
      listenKey(kRtspPort),
      Key::text("name", &OutputConfig::rtspName,
                "the stream's name in its address, rtsp://HOST:PORT/NAME", Shown::kExample),
      encoderKey(),
      crfKey(),
      presetKey(),
      pixelFormatKey(),
      passwordFileKey(),
  };
  type.readSettings = checkRtsp;
  type.conflict = sharesPort;  // one server per output
  type.openPictureSink = openRtsp;
  return type;
}

}  // namespace surroundd::daemon
