#include "daemon/outputs/recording/rig_recorder.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "daemon/config/output_files.hpp"

namespace surroundd::daemon {

RigRecorder::RigRecorder(RecordingSettings settings, std::vector<RigCamera> rig, double nominalFps)
    : settings_(std::move(settings)), rig_(std::move(rig)) {
  createOutputFolder(settings_.folder, settings_.folder);
  bgr_.resize(rig_.size());
  for (auto& camera : rig_) {
    render::VideoEncoderSettings video;
    video.path = settings_.folder / (camera.calibration.name + ".mp4");
    video.size = camera.calibration.intrinsics.imageSize;
    video.nominalFps = nominalFps;
    video.crf = settings_.lossless ? 0 : settings_.crf;
    video.preset = settings_.lossless ? "ultrafast" : settings_.preset;  // lossless either way
    video.pixelFormat = settings_.lossless ? "bgr24" : "yuv444p";
    encoders_.push_back(std::make_unique<render::VideoEncoder>(std::move(video)));
    // The replayed rig: the same calibration, its source this file.
    // The recording replays as a file, whatever the camera was.
    capture::FileSourceSettings file;
    file.path = settings_.folder / (camera.calibration.name + ".mp4");
    camera.source = file;
  }
}

void RigRecorder::record(const capture::FrameSet& set) {
  for (std::size_t c = 0; c < encoders_.size(); ++c) {
    const capture::Frame* frame = set.frame(c);
    if (frame == nullptr) continue;
    if (frame->format == PixelFormat::kBgr) {
      encoders_[c]->write(frame->image, frame->timestamp);
    } else {
      heldToBgr(frame->image, frame->format, bgr_[c]);
      encoders_[c]->write(bgr_[c], frame->timestamp);
    }
  }
}

void RigRecorder::finish() {
  if (finished_) return;
  finished_ = true;
  std::vector<RigCamera> recorded;
  std::string missing;
  for (std::size_t c = 0; c < encoders_.size(); ++c) {
    if (encoders_[c]->framesWritten() == 0) {
      missing += " " + rig_[c].calibration.name;
      try {
        encoders_[c]->close();  // refuses to make an empty video: no file is left, as wanted here
      } catch (const render::EncoderError&) {
      }
      spdlog::warn("recording {}: camera '{}' delivered no frames; it is left out of rig.yaml",
                   settings_.folder.string(), rig_[c].calibration.name);
      continue;
    }
    encoders_[c]->close();
    recorded.push_back(rig_[c]);
  }
  if (recorded.empty()) {
    throw std::runtime_error(
        fmt::format("recording {}: no camera delivered a frame", settings_.folder.string()));
  }
  writeRigFile(settings_.folder / "rig.yaml", recorded,
               missing.empty() ? "recorded by surroundd"
                               : "recorded by surroundd; no frames from:" + missing);
}

std::string RigRecorder::describe() const {
  std::uint64_t frames = 0;
  for (const auto& encoder : encoders_) frames += encoder->framesWritten();
  return fmt::format("recording {} ({} frames of {} cameras, {})", settings_.folder.string(),
                     frames, encoders_.size(), settings_.lossless ? "lossless" : "H.264");
}

}  // namespace surroundd::daemon
