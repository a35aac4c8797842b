#pragma once
// Recording mode: every camera's frames, as captured, each into its own H.264 file with its
// original timestamps (MP4 keeps them to the microsecond), and at the end a rig file whose
// sources are those files, so that surroundd replays the recording frame for frame through
// file-backed virtual cameras. Lossless by default (H.264 on BGR at crf 0: bit for bit).
//
// The folder is complete once rig.yaml is in it: the videos are finalized first (each written
// as <name>.part and renamed), the rig file last (the same way).
//
// Error policy: construction and record()/finish() throw (EncoderError, std::runtime_error)
// naming the file; the pipeline drops a failed recorder like any output.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "capture/frame_set.hpp"
#include "daemon/config/camera_frames_sink.hpp"
#include "daemon/config/rig_yaml.hpp"
#include "render/outputs/video_encoder.hpp"

namespace surroundd::daemon {

struct RecordingSettings {
  std::filesystem::path folder;
  bool lossless = true;  // else H.264 4:4:4 at `crf`
  int crf = 18;
  std::string preset = "veryfast";
};

class RigRecorder final : public CameraFramesSink {
 public:
  RigRecorder(RecordingSettings settings, std::vector<RigCamera> rig, double nominalFps);

  // Writes each camera's frame of the set (an empty slot writes nothing for that camera).
  void record(const capture::FrameSet& set) override;
  // Finalizes the videos and writes rig.yaml. Cameras that recorded nothing are left out of it
  // (with a note in the rig file's header).
  void finish() override;
  std::string describe() const override;

 private:
  RecordingSettings settings_;
  std::vector<RigCamera> rig_;
  std::vector<std::unique_ptr<render::VideoEncoder>> encoders_;
  std::vector<cv::Mat> bgr_;  // per camera: a YUV frame converted for its encoder, reused
  bool finished_ = false;
};

}  // namespace surroundd::daemon
