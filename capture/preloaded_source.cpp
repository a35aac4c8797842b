#include "capture/preloaded_source.hpp"

#include <algorithm>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "capture/jpeg_decoder.hpp"
#include "capture/replay_clock.hpp"

namespace surroundd::capture {
namespace {

// A file broken from some frame on faults at every read; the decode stops after this many faults in
// a row instead of reading for ever.
constexpr int kMaxFaultsInARow = 100;

constexpr double kBytesPerMib = 1024.0 * 1024.0;

// One frame as a camera of the format hands it over.
struct HeldFrame {
  std::vector<std::uint8_t> data;
  Timestamp timestamp{0};  // the file's, of the first pass
  std::string concealed;   // FileSource's message when it was decoded with concealed errors
};

}  // namespace

std::size_t preloadedFrameBytes(PixelLayout format, cv::Size size) {
  const auto pixels = static_cast<std::size_t>(size.width) * static_cast<std::size_t>(size.height);
  return format == PixelLayout::kNv12 ? pixels * 3 / 2 : pixels * 2;
}

struct PreloadedSource::Impl {
  std::string camera;
  PreloadSettings settings;
  cv::Size size;
  Timestamp period{0};
  std::size_t frameBytes = 0;
  std::size_t bytesPerLine = 0;  // of the first (or only) plane
  std::vector<HeldFrame> frames;
  JpegDecoder jpeg;  // convertToBgr's; YUYV and NV12 do not use it
  ReplayPacer pacer{Pacing::kRealtime};
  Timestamp passShift{0};   // how far each loop moves the timestamps on
  Timestamp loopOffset{0};  // added to the first pass's timestamps
  std::size_t next = 0;     // the frame read() gives next
  std::uint64_t framesRead = 0;
  std::string lastError;

  std::string where() const {
    return fmt::format("camera '{}': '{}'", camera, settings.file.path.string());
  }
  [[noreturn]] void fail(std::string_view what) const {
    throw CaptureError(fmt::format("{} {}", where(), what));
  }
  [[noreturn]] void failTooLarge(std::uint64_t frameCount) const;
  void load();
  void checkFormat() const;
};

void PreloadedSource::Impl::failTooLarge(std::uint64_t frameCount) const {
  const auto needed = static_cast<double>(frameCount) * static_cast<double>(frameBytes);
  fail(fmt::format(
      "preloaded as {} needs {:.0f} bytes ({:.1f} MiB: {} frames of {}x{}, {} bytes each), more "
      "than the {} bytes ({:.1f} MiB) allowed{}",
      toString(settings.format), needed, needed / kBytesPerMib, frameCount, size.width, size.height,
      frameBytes, settings.maxBytes, static_cast<double>(settings.maxBytes) / kBytesPerMib,
      settings.maxBytesOrigin.empty() ? "" : " by " + settings.maxBytesOrigin));
}

void PreloadedSource::Impl::checkFormat() const {
  if (settings.format != PixelLayout::kYuyv && settings.format != PixelLayout::kUyvy &&
      settings.format != PixelLayout::kNv12) {
    fail(fmt::format("cannot be preloaded as {}: only as YUYV, UYVY or NV12",
                     toString(settings.format)));
  }
  // YUYV and UYVY share one chroma pair between two pixels of a row; NV12 between 2x2 pixels.
  const bool nv12 = settings.format == PixelLayout::kNv12;
  if (size.width % 2 != 0 || (nv12 && size.height % 2 != 0)) {
    fail(fmt::format("has {}x{} frames, which {} cannot hold (it needs an even width{})",
                     size.width, size.height, toString(settings.format),
                     nv12 ? " and height" : ""));
  }
}

void PreloadedSource::Impl::load() {
  FileSourceSettings once = settings.file;
  once.loop = false;  // one pass; read() loops it
  once.pacing = Pacing::kAsFastAsPossible;
  FileSource source(camera, once);
  size = source.frameSize();
  period = source.nominalPeriod();
  checkFormat();
  frameBytes = preloadedFrameBytes(settings.format, size);
  bytesPerLine = settings.format == PixelLayout::kNv12 ? static_cast<std::size_t>(size.width)
                                                       : static_cast<std::size_t>(size.width) * 2;
  const std::uint64_t fitting = settings.maxBytes / frameBytes;
  // Refused before decoding anything where the file states its length.
  if (source.frameCountHint() > fitting) failTooLarge(source.frameCountHint());
  frames.reserve(static_cast<std::size_t>(std::max<std::uint64_t>(source.frameCountHint(), 1)));

  Frame decoded;
  decoded.image.create(size, CV_8UC3);
  std::uint64_t decodedFrames = 0;
  std::uint64_t faults = 0;
  int faultsInARow = 0;
  std::string firstFault;
  while (true) {
    const ReadStatus status = source.read(decoded);
    if (status == ReadStatus::kEndOfStream) break;
    if (status != ReadStatus::kFrame) {
      if (firstFault.empty()) firstFault = source.lastError();
      ++faults;
      if (++faultsInARow > kMaxFaultsInARow) {
        fail(fmt::format("cannot be preloaded: {} frames in a row do not decode; the last: {}",
                         faultsInARow, source.lastError()));
      }
      continue;
    }
    faultsInARow = 0;
    if (++decodedFrames > fitting) {
      // Over the bound: the frames are let go, and the rest only counted for the message.
      frames = {};
      continue;
    }
    HeldFrame& held = frames.emplace_back();
    held.data.resize(frameBytes);
    held.timestamp = decoded.timestamp;
    if (decoded.concealedErrors) held.concealed = source.lastError();
    cv::Mat into(heldSize(heldFormat(settings.format), size), heldType(heldFormat(settings.format)),
                 held.data.data());
    bgrToHeld(decoded.image, heldFormat(settings.format), into);
  }
  if (decodedFrames > fitting) failTooLarge(decodedFrames);
  if (frames.empty())
    fail(fmt::format("has no frame that decodes; the first fault: {}", firstFault));
  if (faults > 0) {
    spdlog::warn(
        "camera '{}': {} frames of '{}' do not decode and are left out of its preloaded "
        "replay; the first: {}",
        camera, faults, settings.file.path.string(), firstFault);
  }
  const Timestamp first = frames.front().timestamp;
  const Timestamp last = std::ranges::max(frames, {}, &HeldFrame::timestamp).timestamp;
  passShift = loopShift(first, last, period);
}

PreloadedSource::PreloadedSource(std::string cameraName, PreloadSettings settings,
                                 std::shared_ptr<ReplayStart> start)
    : impl_(std::make_unique<Impl>()) {
  impl_->camera = std::move(cameraName);
  impl_->settings = std::move(settings);
  impl_->pacer = ReplayPacer(impl_->settings.file.pacing, std::move(start));
  impl_->load();
}

PreloadedSource::~PreloadedSource() = default;

cv::Size PreloadedSource::frameSize() const { return impl_->size; }

PixelFormat PreloadedSource::pixelFormat() const { return heldFormat(impl_->settings.format); }

Timestamp PreloadedSource::nominalPeriod() const { return impl_->period; }

const std::string& PreloadedSource::lastError() const { return impl_->lastError; }

bool PreloadedSource::repeatsOnePicture() const {
  return impl_->frames.size() == 1 && impl_->settings.file.loop;
}

std::size_t PreloadedSource::frameCount() const { return impl_->frames.size(); }

std::uint64_t PreloadedSource::bytes() const {
  return static_cast<std::uint64_t>(impl_->frames.size()) * impl_->frameBytes;
}

std::span<const std::uint8_t> PreloadedSource::frameData(std::size_t index) const {
  return impl_->frames.at(index).data;
}

ReadStatus PreloadedSource::read(Frame& out) {
  auto& s = *impl_;
  if (s.next == s.frames.size()) {
    if (!s.settings.file.loop) return ReadStatus::kEndOfStream;
    s.next = 0;
    s.loopOffset += s.passShift;
  }
  const HeldFrame& held = s.frames[s.next++];
  const PixelFormat format = pixelFormat();
  if (!holds(out.image, format, s.size)) {
    // The caller's pool should match; rather than write out of bounds, fix it once.
    out.image.create(heldSize(format, s.size), heldType(format));
    out.format = format;
  }
  // What a V4L2 camera's frame of this format goes through (v4l2_source.cpp): the per-frame cost.
  if (!holdFrame(s.settings.format, held.data, s.bytesPerLine, s.jpeg, s.size, out.image,
                 s.lastError)) {
    s.lastError = fmt::format("camera '{}': {}", s.camera, s.lastError);
    return ReadStatus::kFault;
  }
  out.concealedErrors = !held.concealed.empty();
  if (out.concealedErrors) s.lastError = held.concealed;
  out.timestamp = held.timestamp + s.loopOffset;
  out.sequence = s.framesRead++;
  s.pacer.waitFor(out.timestamp);
  return ReadStatus::kFrame;
}

}  // namespace surroundd::capture
