// The `video` and `network` outputs: H.264 through one VideoSink, into a file (segmented or not)
// or as MPEG-TS over UDP; encoding runs on a thread of its own behind a queue.
#include <chrono>

#include <fmt/format.h>

#include "daemon/config/output_files.hpp"
#include "daemon/outputs/built_in_outputs.hpp"
#include "render/outputs/video_sink.hpp"

namespace surroundd::daemon {
namespace {

// Pictures that may wait for an encoder: enough to ride out a slow frame, few enough that a live
// view stays current.
constexpr std::size_t kEncoderQueue = 3;

using Key = ConfigKey<OutputConfig>;

// The container is chosen by the file's extension.
void checkVideo(YamlObject& item, OutputConfig& o) {
  checkEncoder(item, o);
  const auto extension = o.path.extension().string();
  if (extension != ".mp4" && extension != ".mkv") {
    item.error("path",
               fmt::format("expected a file ending in .mp4 or .mkv, got '{}'", o.path.string()));
  }
}

void checkNetwork(YamlObject& item, OutputConfig& o) {
  checkEncoder(item, o);
  if (!o.url.starts_with("udp://") || o.url.size() <= 6) {
    item.error("url", fmt::format("expected udp://HOST:PORT, got '{}'", o.url));
  }
}

std::unique_ptr<render::FrameSink> openVideo(const OutputConfig& output,
                                             const OutputContext& context) {
  if (output.path.has_parent_path()) createOutputFolder(output.path.parent_path(), output.path);
  render::VideoEncoderSettings settings = encoderSettings(output, context);
  settings.path = output.path;
  settings.url = output.url;
  // A viewer of the stream can tell how late it shows each picture.
  settings.stampCaptureTime = !output.url.empty();
  const render::Retention retention{output.family.empty() ? output.path : output.family,
                                    output.keepLast,
                                    static_cast<std::uint64_t>(output.maxMb * 1e6)};
  auto video =
      std::make_unique<render::VideoSink>(std::move(settings),
                                          std::chrono::duration_cast<std::chrono::nanoseconds>(
                                              std::chrono::duration<double>(output.segmentS)),
                                          retention);
  // Encoding runs beside the next frame set's stitching; live, the newest picture wins.
  return queuedSink(std::move(video), context, kEncoderQueue);
}

}  // namespace

ConfigKey<OutputConfig> presetKey() {
  return Key::choice("preset", &OutputConfig::preset,
                     {{"ultrafast", "ultrafast"},
                      {"superfast", "superfast"},
                      {"veryfast", "veryfast"},
                      {"faster", "faster"},
                      {"fast", "fast"},
                      {"medium", "medium"}},
                     "x264 speed preset");
}

ConfigKey<OutputConfig> encoderKey() {
  return Key::text("encoder", &OutputConfig::encoder,
                   "the H.264 encoder: auto (the first of h264_nvenc, h264_vaapi, h264_v4l2m2m "
                   "that opens here, else libx264; the log says which) | libx264 | an FFmpeg "
                   "encoder's name");
}

// An encoder this FFmpeg has, and H.264 (whether its device is there shows only when it opens).
void checkEncoder(YamlObject& item, OutputConfig& o) {
  if (const auto problem = render::h264EncoderProblem(o.encoder)) item.error("encoder", *problem);
}

ConfigKey<OutputConfig> pixelFormatKey() {
  return Key::choice("pixel_format", &OutputConfig::pixelFormat,
                     {{"yuv420p", "yuv420p"}, {"yuv444p", "yuv444p"}}, "the encoded pixel format");
}

render::VideoEncoderSettings encoderSettings(const OutputConfig& output,
                                             const OutputContext& context) {
  render::VideoEncoderSettings settings;
  settings.size = context.pictureSize;
  settings.nominalFps = context.nominalFps;
  settings.crf = output.crf;
  settings.preset = output.preset;
  settings.pixelFormat = output.pixelFormat;
  settings.encoder = output.encoder;
  return settings;
}

ConfigKey<OutputConfig> crfKey() {
  return Key::integer("crf", &OutputConfig::crf, 0, 51, "x264 constant rate factor");
}

OutputType videoOutputType() {
  OutputType type;
  type.name = "video";
  type.keys = {
      Key::requiredPath("path", &OutputConfig::path, "the file: .mp4 or .mkv (H.264)"),
      encoderKey(),
      crfKey(),
      presetKey(),
      pixelFormatKey(),
      Key::number("segment_s", &OutputConfig::segmentS, {0.0, 86400.0, false, "seconds"},
                  "a new file every this many seconds of stream time"),
      Key::integer("keep_last", &OutputConfig::keepLast, 0, 1'000'000,
                   "the newest files of it kept (segments, or this run's and earlier runs'); 0: "
                   "all"),
      Key::number("max_mb", &OutputConfig::maxMb, {0.0, 1e9, false, "MB"},
                  "MB its files may hold together, the oldest removed first; 0: no limit"),
  };
  type.readSettings = checkVideo;
  type.pathUse = [](const OutputConfig& o) {
    return o.segmentS > 0 ? OutputPathUse::kSegments : OutputPathUse::kKept;
  };
  type.openPictureSink = openVideo;
  return type;
}

OutputType networkOutputType() {
  OutputType type;
  type.name = "network";
  type.keys = {
      Key::text("url", &OutputConfig::url, "where the stream goes, udp://HOST:PORT",
                Shown::kExample),
      encoderKey(),
      crfKey(),
      presetKey(),
      pixelFormatKey(),
  };
  type.readSettings = checkNetwork;
  type.openPictureSink = openVideo;
  return type;
}

}  // namespace surroundd::daemon
