// The `recording` output: every camera's own stream into a folder, with a rig file that replays
// it (RigRecorder).
#include <filesystem>

#include <fmt/format.h>

#include "daemon/outputs/built_in_outputs.hpp"
#include "daemon/outputs/rig_recorder.hpp"

namespace surroundd::daemon {
namespace {

void checkRecording(YamlObject& item, OutputConfig& o) {
  if (item.has("stream")) {
    item.error("stream", "a recording writes every camera's own stream; it takes no 'stream'");
  }
  std::error_code ec;
  if (!o.path.empty() && std::filesystem::exists(o.path, ec) &&
      !std::filesystem::is_directory(o.path, ec)) {
    item.error("path", fmt::format("expected a folder for the recording, got the file '{}'",
                                   o.path.string()));
  }
}

std::unique_ptr<CameraFramesSink> openRecording(const OutputConfig& output,
                                                const OutputContext& context) {
  return std::make_unique<RigRecorder>(
      RecordingSettings{output.path, output.lossless, output.crf, output.preset}, *context.cameras,
      context.nominalFps);
}

}  // namespace

OutputType recordingOutputType() {
  OutputType type;
  type.name = "recording";
  type.input = OutputInput::kCameraFrames;
  using Key = ConfigKey<OutputConfig>;
  type.keys = {
      Key::requiredPath("path", &OutputConfig::path, "the folder written"),
      Key::flag("lossless", &OutputConfig::lossless, "bit for bit"),
      crfKey(),
  };
  type.readSettings = checkRecording;
  type.pathUse = [](const OutputConfig&) { return OutputPathUse::kFolder; };
  type.openCameraFramesSink = openRecording;
  return type;
}

}  // namespace surroundd::daemon
