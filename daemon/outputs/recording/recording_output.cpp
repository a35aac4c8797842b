#include "daemon/outputs/recording/recording_output.hpp"

#include <filesystem>

#include <fmt/format.h>

#include "daemon/outputs/recording/rig_recorder.hpp"

namespace surroundd::daemon {
namespace {

void checkRecording(YamlObject& item, const OutputConfig& o,
                    const RecordingOutputSettings& /*settings*/) {
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
  const auto& own = settingsOf<RecordingOutputSettings>(output);
  return std::make_unique<RigRecorder>(
      RecordingSettings{output.path, own.lossless, own.h264.crf, own.h264.preset}, *context.cameras,
      context.nominalFps);
}

}  // namespace

OutputType recordingOutputType() {
  OutputType type;
  type.name = "recording";
  type.input = OutputInput::kCameraFrames;
  type.pathDoc = "the folder written";
  readsSettings<RecordingOutputSettings>(
      type,
      {
          ConfigKey<RecordingOutputSettings>::flag("lossless", &RecordingOutputSettings::lossless,
                                                   "bit for bit"),
          crfKey<RecordingOutputSettings>(),
      },
      checkRecording);
  type.pathUse = [](const OutputConfig&) { return OutputPathUse::kFolder; };
  type.openCameraFramesSink = openRecording;
  return type;
}

}  // namespace surroundd::daemon
