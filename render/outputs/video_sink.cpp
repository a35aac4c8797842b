#include "render/outputs/video_sink.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace surroundd::render {

VideoSink::VideoSink(VideoEncoderSettings settings, std::chrono::nanoseconds segmentLength,
                     Retention retention)
    : settings_(std::move(settings)),
      segmentLength_(segmentLength),
      retention_(std::move(retention)) {
  if (segmentLength_.count() > 0) {
    const auto present = numberedFiles(settings_.path);
    firstSegment_ = (present.empty() ? 0 : present.back().number) + 1;
    if (firstSegment_ > kMaxFileNumber) {
      throw EncoderError(
          fmt::format("{}: the segments beside it are numbered up to {}, the most "
                      "there can be: move them away",
                      segmentPath(firstSegment_ - 1).string(), kMaxFileNumber));
    }
    segment_ = firstSegment_ - 1;
  }
  openSegment();
  takesI420_ = encoder_->takesI420();
}

std::filesystem::path VideoSink::segmentPath(std::int64_t number) const {
  auto path = settings_.path;
  path.replace_filename(fmt::format("{}-{:05}{}", settings_.path.stem().string(), number,
                                    settings_.path.extension().string()));
  return path;
}

void VideoSink::openSegment() {
  VideoEncoderSettings settings = settings_;
  if (segmentLength_.count() > 0) settings.path = segmentPath(++segment_);
  encoder_.reset();  // finalizes the previous segment first
  const std::filesystem::path writing = settings.path;
  encoder_.emplace(std::move(settings));
  if (retention_.limits()) {
    for (const auto& removed : retainNewest(retention_, writing)) {
      spdlog::info("video {}: removed {} (its retention: {})", writing.string(), removed.string(),
                   render::describe(retention_));
    }
  }
  // The next segments go on with the encoder this one found, without trying the others again.
  if (settings_.encoder == "auto" && !encoder_->encoderName().starts_with("libx264")) {
    settings_.encoder = encoder_->encoderName();
  } else if (settings_.encoder == "auto") {
    settings_.encoder = "libx264";
  }
}

void VideoSink::consume(const cv::Mat& picture, const PictureTime& time) {
  const std::chrono::nanoseconds streamTime = time.stream;
  if (segmentLength_.count() > 0) {
    // Segments cover whole multiples of their length in stream time: [0, L), [L, 2L), ...
    const auto window = streamTime.count() / segmentLength_.count();
    if (window_ && window != *window_) {
      encoder_->close();  // throws if it cannot be finalized: the pipeline then drops this output
      openSegment();
    }
    window_ = window;
  }
  encoder_->write(picture, streamTime, time.captured);
  ++frames_;
}

void VideoSink::finish(const cv::Mat& /*lastFrame*/, std::chrono::nanoseconds /*lastTime*/) {
  encoder_->close();
}

std::string VideoSink::describe() const {
  const std::string kind = settings_.url.empty() ? "video" : "stream";
  if (segmentLength_.count() == 0) {
    return fmt::format("{} {} ({} frames)", kind, encoder_->target(), frames_);
  }
  return fmt::format("video {} .. {} ({} segments, {} frames)", segmentPath(firstSegment_).string(),
                     segmentPath(segment_).filename().string(), segment_ - firstSegment_ + 1,
                     frames_);
}

}  // namespace surroundd::render
