#pragma once
// Where rendered frames go. Each output in the config is one FrameSink; the pipeline hands every
// sink each frame it wants, in stream order, then finish() once.
//
// Error policy: consume() and finish() throw (EncoderError, std::runtime_error) naming the file;
// the pipeline logs the failure and drops that sink, the others go on.

#include <chrono>
#include <cstdint>
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
  // Pictures it was given but dropped because it fell behind (see QueuedSink).
  virtual std::uint64_t dropped() const { return 0; }
};

// H.264 video (see VideoEncoder): one file, a network stream, or files of `segmentLength` stream
// time each ([0, L), [L, 2L), ... from the first frame set), named <stem>-00001<ext>,
// <stem>-00002<ext>, ... and each finalized when the next begins, so that a crash or power loss
// costs at most the segment being written. Numbering goes on after the highest segment already in
// the folder: a restart never overwrites one.
class VideoSink final : public FrameSink {
 public:
  // Opens the file (the first segment) or the stream; throws EncoderError naming it.
  explicit VideoSink(VideoEncoderSettings settings,
                     std::chrono::nanoseconds segmentLength = std::chrono::nanoseconds(0));
  void consume(const cv::Mat& bgr, std::chrono::nanoseconds streamTime) override;
  void finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) override;
  std::string describe() const override;

 private:
  std::filesystem::path segmentPath(std::int64_t number) const;
  void openSegment();

  VideoEncoderSettings settings_;
  std::chrono::nanoseconds segmentLength_;  // 0: one file
  std::optional<VideoEncoder> encoder_;
  std::optional<std::int64_t> window_;  // which multiple of segmentLength_ is being written
  std::int64_t firstSegment_ = 1;
  std::int64_t segment_ = 0;  // the one being written
  std::uint64_t frames_ = 0;
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
