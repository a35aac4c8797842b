#pragma once
// Where rendered frames go. Each output in the config is one FrameSink; the pipeline hands every
// sink each frame it wants, in stream order, then finish() once.
//
// Error policy: consume() and finish() throw (EncoderError, std::runtime_error) naming the file;
// the pipeline logs the failure and drops that sink, the others go on.

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "render/video_encoder.hpp"

namespace surroundd::render {

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  FrameSink() = default;
  FrameSink(const FrameSink&) = delete;
  FrameSink& operator=(const FrameSink&) = delete;

  // `bgr` is 8-bit BGR; `streamTime` counts from the first frame of the run.
  virtual void consume(const cv::Mat& bgr, std::chrono::nanoseconds streamTime) = 0;
  // Whether the frame at `streamTime` is needed: the pipeline skips making pictures (renders) that
  // no sink wants.
  virtual bool wantsFrame(std::chrono::nanoseconds /*streamTime*/) const { return true; }
  // The run is over; `lastFrame` is the picture of the run's last frame, at `lastTime` (empty if
  // there was none).
  virtual void finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) = 0;
  // What was written, for the log ("video /out/demo/mosaic.mp4 (300 frames)").
  virtual std::string describe() const = 0;
};

// H.264 video file (see VideoEncoder).
class VideoFileSink final : public FrameSink {
 public:
  explicit VideoFileSink(VideoEncoderSettings settings) : encoder_(std::move(settings)) {}
  void consume(const cv::Mat& bgr, std::chrono::nanoseconds streamTime) override;
  void finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) override;
  std::string describe() const override;

 private:
  VideoEncoder encoder_;
};

// One still image of the frame at `at` stream time, or of the last frame if the run is shorter.
class SnapshotSink final : public FrameSink {
 public:
  SnapshotSink(std::filesystem::path path, std::chrono::nanoseconds at);
  void consume(const cv::Mat& bgr, std::chrono::nanoseconds streamTime) override;
  bool wantsFrame(std::chrono::nanoseconds streamTime) const override {
    return !writtenAt_ && streamTime >= at_;
  }
  void finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) override;
  std::string describe() const override;

 private:
  std::filesystem::path path_;
  std::chrono::nanoseconds at_;
  std::optional<std::chrono::nanoseconds> writtenAt_;
};

}  // namespace surroundd::render
