#include "render/outputs/snapshot_sink.hpp"

#include <fmt/format.h>

#include "render/outputs/image_file.hpp"

namespace surroundd::render {

SnapshotSink::SnapshotSink(std::filesystem::path path, std::chrono::nanoseconds at)
    : path_(std::move(path)), at_(at) {}

void SnapshotSink::consume(const cv::Mat& bgr, const PictureTime& time) {
  if (!wantsFrame(time.stream)) return;
  writeImageFile(path_, bgr);
  writtenAt_ = time.stream;
}

void SnapshotSink::finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) {
  if (writtenAt_ || lastFrame.empty()) return;
  writeImageFile(path_, lastFrame);
  writtenAt_ = lastTime;
}

std::string SnapshotSink::describe() const {
  if (!writtenAt_) return fmt::format("snapshot {} (not written: no frames)", path_.string());
  return fmt::format("snapshot {} (at {:.3f} s)", path_.string(),
                     std::chrono::duration<double>(*writtenAt_).count());
}

}  // namespace surroundd::render
