#include <fmt/format.h>

#include "render/frame_sink.hpp"

namespace surroundd::render {

void VideoFileSink::consume(const cv::Mat& bgr, std::chrono::nanoseconds streamTime) {
  encoder_.write(bgr, streamTime);
}

void VideoFileSink::finish(const cv::Mat& /*lastFrame*/, std::chrono::nanoseconds /*lastTime*/) {
  encoder_.close();
}

std::string VideoFileSink::describe() const {
  return fmt::format("video {} ({} frames)", encoder_.path().string(), encoder_.framesWritten());
}

}  // namespace surroundd::render
