#pragma once
// H.264 video written by a VideoEncoder, as a FrameSink: the `video` and `network` outputs.
//
// Error policy: as FrameSink's; the constructor throws EncoderError naming the file or stream.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "render/outputs/frame_sink.hpp"
#include "render/outputs/numbered_files.hpp"
#include "render/outputs/video_encoder.hpp"

namespace surroundd::render {

// H.264 video (see VideoEncoder): one file, a network stream, or files of `segmentLength` stream
// time each ([0, L), [L, 2L), ... from the first frame set), named <stem>-00001<ext>,
// <stem>-00002<ext>, ... and each finalized when the next begins, so that a crash or power loss
// costs at most the segment being written. Numbering goes on after the highest segment already in
// the folder: a restart never overwrites one. With a retention, each file opened (a run's, a
// segment) removes the oldest of its family's beyond it (numbered_files.hpp).
class VideoSink final : public FrameSink {
 public:
  // Opens the file (the first segment) or the stream; throws EncoderError naming it.
  explicit VideoSink(VideoEncoderSettings settings,
                     std::chrono::nanoseconds segmentLength = std::chrono::nanoseconds(0),
                     Retention retention = {});
  void consume(const cv::Mat& picture, const PictureTime& time) override;
  bool takesI420() const override { return takesI420_; }
  void finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) override;
  std::string describe() const override;

 private:
  std::filesystem::path segmentPath(std::int64_t number) const;
  void openSegment();

  VideoEncoderSettings settings_;
  std::chrono::nanoseconds segmentLength_;  // 0: one file
  Retention retention_;
  std::optional<VideoEncoder> encoder_;
  std::optional<std::int64_t> window_;  // which multiple of segmentLength_ is being written
  std::int64_t firstSegment_ = 1;
  std::int64_t segment_ = 0;  // the one being written
  std::uint64_t frames_ = 0;
  // Every segment's encoder's: kept here, as the pipeline thread asks it while a queue's thread
  // may be opening the next segment.
  bool takesI420_ = false;
};

}  // namespace surroundd::render
