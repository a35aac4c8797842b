#pragma once
// The `recording` output type: every camera's own stream into a folder, with a rig file that
// replays it (RigRecorder).

#include "daemon/config/output_type.hpp"
#include "daemon/outputs/h264_settings.hpp"

namespace surroundd::daemon {

struct RecordingOutputSettings {
  bool lossless = true;  // bit for bit; else H.264 4:4:4 at h264.crf and h264.preset
  H264Settings h264;

  bool operator==(const RecordingOutputSettings&) const = default;
};

OutputType recordingOutputType();

}  // namespace surroundd::daemon
