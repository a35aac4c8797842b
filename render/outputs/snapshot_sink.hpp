#pragma once
// A PNG snapshot as a FrameSink: the `snapshot` output. The file is written whole, then renamed
// (image_file.hpp), so a reader never sees half a picture.

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>

#include "render/outputs/frame_sink.hpp"

namespace surroundd::render {

// One still image of the frame at `at` stream time, or of the last frame if the run is shorter.
class SnapshotSink final : public FrameSink {
 public:
  SnapshotSink(std::filesystem::path path, std::chrono::nanoseconds at);
  void consume(const cv::Mat& bgr, const PictureTime& time) override;
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
