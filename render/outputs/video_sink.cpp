#include "render/outputs/video_sink.hpp"

#include <algorithm>
#include <charconv>

#include <fmt/format.h>

namespace surroundd::render {
namespace {

// Numbers above this are refused rather than let to wrap (a stray "seg-9223372036854775807").
constexpr std::int64_t kMaxSegment = 999'999'999'999;

// The highest N of the <stem>-N<ext> files next to `path` (or their .part files: a segment a
// killed run left unfinished is kept too), or 0; any N past kMaxSegment counts as kMaxSegment (a
// stray "seg-9223372036854775807" made the next number wrap to a negative one).
std::int64_t lastSegmentIn(const std::filesystem::path& path) {
  const auto folder = path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
  const std::string stem = path.stem().string();
  const std::string extension = path.extension().string();
  std::int64_t last = 0;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    std::string name = entry.path().filename().string();
    if (name.ends_with(".part")) name.resize(name.size() - 5);
    if (!name.starts_with(stem + "-") || !name.ends_with(extension)) continue;
    const std::string_view digits(name.data() + stem.size() + 1,
                                  name.size() - stem.size() - 1 - extension.size());
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string_view::npos) {
      continue;
    }
    std::uint64_t number = 0;
    const auto [end, failed] =
        std::from_chars(digits.data(), digits.data() + digits.size(), number);
    const bool past = failed == std::errc::result_out_of_range ||
                      number > static_cast<std::uint64_t>(kMaxSegment);
    last = std::max(last, past ? kMaxSegment : static_cast<std::int64_t>(number));
  }
  return last;
}

}  // namespace

VideoSink::VideoSink(VideoEncoderSettings settings, std::chrono::nanoseconds segmentLength)
    : settings_(std::move(settings)), segmentLength_(segmentLength) {
  if (segmentLength_.count() > 0) {
    firstSegment_ = lastSegmentIn(settings_.path) + 1;
    if (firstSegment_ > kMaxSegment) {
      throw EncoderError(
          fmt::format("{}: the segments beside it are numbered up to {}, the most "
                      "there can be: move them away",
                      segmentPath(firstSegment_ - 1).string(), kMaxSegment));
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
  encoder_.emplace(std::move(settings));
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
