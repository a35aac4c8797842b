// Encoding runs on a thread of its own behind a queue.
#include "daemon/outputs/video/video_output.hpp"

#include <chrono>

#include <fmt/format.h>

#include "daemon/config/output_files.hpp"
#include "render/outputs/video_sink.hpp"

namespace surroundd::daemon {
namespace {

// Pictures that may wait for an encoder: enough to ride out a slow frame, few enough that a live
// view stays current.
constexpr std::size_t kEncoderQueue = 3;

// The container is chosen by the file's extension.
void checkVideo(YamlObject& item, const OutputConfig& o, const VideoOutputSettings& settings) {
  checkEncoder(item, settings.h264);
  const auto extension = o.path.extension().string();
  if (extension != ".mp4" && extension != ".mkv") {
    item.error("path",
               fmt::format("expected a file ending in .mp4 or .mkv, got '{}'", o.path.string()));
  }
}

void checkNetwork(YamlObject& item, const OutputConfig& /*o*/,
                  const NetworkOutputSettings& settings) {
  checkEncoder(item, settings.h264);
  if (!settings.url.starts_with("udp://") || settings.url.size() <= 6) {
    item.error("url", fmt::format("expected udp://HOST:PORT, got '{}'", settings.url));
  }
}

// Encoding runs beside the next frame set's stitching; live, the newest picture wins.
std::unique_ptr<render::FrameSink> queued(render::VideoEncoderSettings settings,
                                          const OutputContext& context, double segmentS,
                                          const render::Retention& retention) {
  auto video = std::make_unique<render::VideoSink>(
      std::move(settings),
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(segmentS)),
      retention);
  return queuedSink(std::move(video), context, kEncoderQueue);
}

std::unique_ptr<render::FrameSink> openVideo(const OutputConfig& output,
                                             const OutputContext& context) {
  const auto& own = settingsOf<VideoOutputSettings>(output);
  if (output.path.has_parent_path()) createOutputFolder(output.path.parent_path(), output.path);
  render::VideoEncoderSettings settings = encoderSettings(own.h264, context);
  settings.path = output.path;
  const render::Retention retention{output.family.empty() ? output.path : output.family,
                                    own.keepLast, static_cast<std::uint64_t>(own.maxMb * 1e6)};
  return queued(std::move(settings), context, own.segmentS, retention);
}

std::unique_ptr<render::FrameSink> openNetwork(const OutputConfig& output,
                                               const OutputContext& context) {
  const auto& own = settingsOf<NetworkOutputSettings>(output);
  render::VideoEncoderSettings settings = encoderSettings(own.h264, context);
  settings.url = own.url;
  // A viewer of the stream can tell how late it shows each picture.
  settings.stampCaptureTime = true;
  return queued(std::move(settings), context, 0, {});
}

}  // namespace

OutputType videoOutputType() {
  OutputType type;
  type.name = "video";
  type.pathDoc = "the file: .mp4 or .mkv (H.264)";
  using Key = ConfigKey<VideoOutputSettings>;
  std::vector<Key> keys = h264Keys<VideoOutputSettings>();
  keys.insert(
      keys.end(),
      {
          Key::number("segment_s", &VideoOutputSettings::segmentS, {0.0, 86400.0, false, "seconds"},
                      "a new file every this many seconds of stream time"),
          Key::integer("keep_last", &VideoOutputSettings::keepLast, 0, 1'000'000,
                       "the newest files of it kept (segments, or this run's and earlier "
                       "runs'); 0: all"),
          Key::number("max_mb", &VideoOutputSettings::maxMb, {0.0, 1e9, false, "MB"},
                      "MB its files may hold together, the oldest removed first; 0: no "
                      "limit"),
      });
  readsSettings<VideoOutputSettings>(type, ConfigKeys(std::move(keys)), checkVideo);
  type.pathUse = [](const OutputConfig& o) {
    return settingsOf<VideoOutputSettings>(o).segmentS > 0 ? OutputPathUse::kSegments
                                                           : OutputPathUse::kKept;
  };
  type.openPictureSink = openVideo;
  return type;
}

OutputType networkOutputType() {
  OutputType type;
  type.name = "network";
  using Key = ConfigKey<NetworkOutputSettings>;
  std::vector<Key> keys{Key::text("url", &NetworkOutputSettings::url,
                                  "where the stream goes, udp://HOST:PORT", Shown::kExample)};
  for (auto& key : h264Keys<NetworkOutputSettings>()) keys.push_back(std::move(key));
  readsSettings<NetworkOutputSettings>(type, ConfigKeys(std::move(keys)), checkNetwork);
  type.openPictureSink = openNetwork;
  return type;
}

}  // namespace surroundd::daemon
