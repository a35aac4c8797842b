// The `video` and `network` outputs: H.264 through one VideoSink, into a file (segmented or not)
// or as MPEG-TS over UDP; encoding runs on a thread of its own behind a queue.
#include <chrono>

#include <fmt/format.h>

#include "daemon/built_in_outputs.hpp"
#include "daemon/output_files.hpp"
#include "render/outputs/video_sink.hpp"

namespace surroundd::daemon {
namespace {

// Pictures that may wait for an encoder: enough to ride out a slow frame, few enough that a live
// view stays current.
constexpr std::size_t kEncoderQueue = 3;

// The encoder's keys, shared by both types.
void readEncoding(YamlObject& item, OutputConfig& o) {
  o.crf = item.integer("crf", o.crf, 0, 51);
  o.preset = item.choice<std::string>("preset", o.preset,
                                      {{"ultrafast", "ultrafast"},
                                       {"superfast", "superfast"},
                                       {"veryfast", "veryfast"},
                                       {"faster", "faster"},
                                       {"fast", "fast"},
                                       {"medium", "medium"}});
  o.pixelFormat = item.choice<std::string>("pixel_format", o.pixelFormat,
                                           {{"yuv420p", "yuv420p"}, {"yuv444p", "yuv444p"}});
}

void readVideo(YamlObject& item, OutputConfig& o) {
  o.path = item.outputPath("path").value_or("");
  readEncoding(item, o);
  o.segmentS = item.number("segment_s", o.segmentS, {0.0, 86400.0, false, "seconds"});
  const auto extension = o.path.extension().string();
  if (extension != ".mp4" && extension != ".mkv") {
    item.error("path",
               fmt::format("expected a file ending in .mp4 or .mkv, got '{}'", o.path.string()));
  }
}

void readNetwork(YamlObject& item, OutputConfig& o) {
  o.url = item.string("url", "");
  if (!o.url.starts_with("udp://") || o.url.size() <= 6) {
    item.error("url", fmt::format("expected udp://HOST:PORT, got '{}'", o.url));
  }
  readEncoding(item, o);
}

std::unique_ptr<render::FrameSink> openVideo(const OutputConfig& output,
                                             const OutputContext& context) {
  if (output.path.has_parent_path()) createOutputFolder(output.path.parent_path(), output.path);
  render::VideoEncoderSettings settings;
  settings.path = output.path;
  settings.size = context.pictureSize;
  settings.nominalFps = context.nominalFps;
  settings.crf = output.crf;
  settings.preset = output.preset;
  settings.pixelFormat = output.pixelFormat;
  settings.url = output.url;
  auto video = std::make_unique<render::VideoSink>(
      std::move(settings), std::chrono::duration_cast<std::chrono::nanoseconds>(
                               std::chrono::duration<double>(output.segmentS)));
  // Encoding runs beside the next frame set's stitching; live, the newest picture wins.
  return queuedSink(std::move(video), context, kEncoderQueue);
}

}  // namespace

OutputType videoOutputType() {
  OutputType type;
  type.name = "video";
  type.readSettings = readVideo;
  type.pathUse = [](const OutputConfig& o) {
    return o.segmentS > 0 ? OutputPathUse::kSegments : OutputPathUse::kKept;
  };
  type.openPictureSink = openVideo;
  return type;
}

OutputType networkOutputType() {
  OutputType type;
  type.name = "network";
  type.readSettings = readNetwork;
  type.openPictureSink = openVideo;
  return type;
}

}  // namespace surroundd::daemon
