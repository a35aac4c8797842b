#include "capture/file_source.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <optional>
#include <string_view>

#include <fmt/format.h>

#include "capture/sequence_pattern.hpp"
#include "common/ffmpeg_util.hpp"

extern "C" {
#include <libavutil/pixdesc.h>
}

namespace surroundd::capture {
namespace {

constexpr AVRational kNanoseconds{1, 1'000'000'000};
constexpr int kSwsFlags = SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT;
// The decoder's own messages about corrupt data (one or more per damaged frame, straight to stderr)
// are moved down to debug level: each damaged frame is a fault with the camera's name instead,
// counted and logged with rate limiting by the recovery policy.
constexpr int kDecoderLogOffset = AV_LOG_DEBUG - AV_LOG_ERROR;

// What FFmpeg says about a frame it decoded with errors and concealed them.
std::string concealedErrorsOf(const AVFrame& frame) {
  std::string what;
  const auto add = [&what](const char* part) {
    what += (what.empty() ? "" : ", ") + std::string(part);
  };
  if ((frame.decode_error_flags & FF_DECODE_ERROR_INVALID_BITSTREAM) != 0) add("invalid bitstream");
  if ((frame.decode_error_flags & FF_DECODE_ERROR_MISSING_REFERENCE) != 0) add("missing reference");
  if ((frame.decode_error_flags & FF_DECODE_ERROR_CONCEALMENT_ACTIVE) != 0) add("concealed");
  if ((frame.decode_error_flags & FF_DECODE_ERROR_DECODE_SLICES) != 0) add("slices lost");
  if (what.empty() && (frame.flags & AV_FRAME_FLAG_CORRUPT) != 0) add("corrupt");
  return what;
}

// FFmpeg's demuxers for pictures: image2 (a pattern, or one named file) and the per-format pipes
// (png_pipe, jpeg_pipe, ...). Their frame rate is a made-up default, not the file's.
bool isPictureDemuxer(std::string_view name) {
  return name == "image2" || name == "image2pipe" || name.ends_with("_pipe");
}

int swsColorspaceOf(AVColorSpace space) {
  switch (space) {
    case AVCOL_SPC_BT709:
      return SWS_CS_ITU709;
    case AVCOL_SPC_FCC:
      return SWS_CS_FCC;
    case AVCOL_SPC_SMPTE240M:
      return SWS_CS_SMPTE240M;
    case AVCOL_SPC_BT2020_NCL:
    case AVCOL_SPC_BT2020_CL:
      return SWS_CS_BT2020;
    default:  // BT.601 (BT470BG, SMPTE170M) and untagged streams
      return SWS_CS_ITU601;
  }
}

}  // namespace

struct FileSource::Impl {
  std::string camera;
  FileSourceSettings settings;
  ffmpeg::InputFormatPtr format;
  ffmpeg::CodecContextPtr codec;
  ffmpeg::PacketPtr packet;
  ffmpeg::FramePtr decoded;
  ffmpeg::SwsContextPtr sws;
  int streamIndex = -1;
  AVRational timeBase{};
  cv::Size size;
  Timestamp period{};
  std::string lastError;
  // One picture (a still, or a sequence of one): decoded and converted once, into `still`.
  bool onePicture = false;
  cv::Mat still;

  // What `sws` was built and set up for; a frame that differs updates it.
  AVPixelFormat swsFormat = AV_PIX_FMT_NONE;
  int swsDefaultRange = 0;  // swscale's own guess for the format (full range for yuvj and gray)
  AVColorSpace swsColorspace = AVCOL_SPC_UNSPECIFIED;
  AVColorRange swsRange = AVCOL_RANGE_UNSPECIFIED;

  bool haveDecoded = false;  // `decoded` holds a frame not yet returned (the one probed at start)
  bool draining = false;     // the demuxer is done; the decoder is being flushed
  std::uint64_t framesRead = 0;  // since the start, across loops
  bool drainFailed = false;      // the decoder failed while being flushed: it has nothing more
  Timestamp loopOffset{0};       // added to timestamps after each loop so they keep increasing
  Timestamp firstTimestamp{0};
  Timestamp lastTimestamp{0};  // latest of this pass through the file, without loopOffset
  ReplayPacer pacer{Pacing::kRealtime};
  std::uint64_t frameCountHint = 0;

  std::string describe(std::string_view what, int error) const {
    return fmt::format("camera '{}': {} '{}': {}", camera, what, settings.path.string(),
                       ffmpeg::errorText(error));
  }
  [[noreturn]] void fail(std::string_view what) const {
    throw CaptureError(fmt::format("camera '{}': '{}' {}", camera, settings.path.string(), what));
  }

  void open();
  // Decodes the next frame into `decoded`. 1: a frame, 0: end of stream, <0: an FFmpeg error after
  // which decoding can go on.
  int decodeNext();
  bool restart();
  bool convert(cv::Mat& out);
  bool setUpConverter(const AVFrame& frame);
  Timestamp timestampOf(const AVFrame& frame) const;
  ReadStatus fault(std::string message);
  std::uint64_t countFrames(const AVStream& stream) const;
};

void FileSource::Impl::open() {
  const FileNameKind kind = classifyFileName(settings.path.string());
  if (kind == FileNameKind::kTooWide) {
    fail(fmt::format("is an image sequence pattern with a number wider than {} digits",
                     kMaxSequenceDigits));
  }
  const bool sequence = kind == FileNameKind::kSequence;
  if (sequence && !(settings.sequenceFps > 0 && std::isfinite(settings.sequenceFps))) {
    fail(fmt::format("needs a positive frame rate, got {}", settings.sequenceFps));
  }
  AVDictionary* options = nullptr;
  const AVInputFormat* input = nullptr;
  if (sequence) {
    input = av_find_input_format("image2");
    av_dict_set(&options, "framerate", fmt::format("{}", settings.sequenceFps).c_str(), 0);
  }
  AVFormatContext* raw = nullptr;
  const int opened = avformat_open_input(&raw, settings.path.c_str(), input, &options);
  av_dict_free(&options);
  if (opened < 0) throw CaptureError(describe("cannot open", opened));
  format.reset(raw);
  if (const int error = avformat_find_stream_info(format.get(), nullptr); error < 0) {
    throw CaptureError(describe("cannot read the stream information of", error));
  }
  const AVCodec* decoder = nullptr;
  streamIndex = av_find_best_stream(format.get(), AVMEDIA_TYPE_VIDEO, -1, -1, &decoder, 0);
  if (streamIndex == AVERROR_DECODER_NOT_FOUND || (streamIndex >= 0 && decoder == nullptr)) {
    fail("has a video stream, but this FFmpeg has no decoder for its codec");
  }
  if (streamIndex < 0) fail("has no video stream");
  const AVStream* stream = format->streams[streamIndex];
  timeBase = stream->time_base;
  codec.reset(avcodec_alloc_context3(decoder));
  if (!codec) fail("cannot be decoded: out of memory");
  if (const int error = avcodec_parameters_to_context(codec.get(), stream->codecpar); error < 0) {
    throw CaptureError(describe("cannot set up the decoder for", error));
  }
  // One decoding thread: the pipeline already runs one capture thread per camera.
  codec->thread_count = 1;
  codec->log_level_offset = kDecoderLogOffset;
  if (const int error = avcodec_open2(codec.get(), decoder, nullptr); error < 0) {
    throw CaptureError(describe("cannot open the decoder for", error));
  }
  size = {codec->width, codec->height};
  if (size.width <= 0 || size.height <= 0) fail("has no frame size");
  const bool pictures = isPictureDemuxer(format->iformat->name);
  // image2 counts a pattern's files: its duration is in frames (time base 1 / framerate).
  onePicture = pictures && (!sequence || stream->duration == 1);
  AVRational rate = stream->avg_frame_rate;
  if (rate.num <= 0 || rate.den <= 0) rate = stream->r_frame_rate;
  const double fps =
      pictures || rate.num <= 0 || rate.den <= 0 ? settings.sequenceFps : av_q2d(rate);
  if (!(fps > 0 && std::isfinite(fps))) {
    fail(fmt::format("needs a positive frame rate (sequence_fps), got {}", fps));
  }
  period = std::chrono::nanoseconds(std::llround(1e9 / fps));
  frameCountHint = countFrames(*stream);
  lastTimestamp = -period;  // an untimed first frame is at 0
  packet.reset(av_packet_alloc());
  decoded.reset(av_frame_alloc());
  if (!packet || !decoded) fail("cannot be decoded: out of memory");

  // Decode the first frame now: a file whose header parses but whose data does not fails at start.
  const int first = decodeNext();
  if (first == 0) fail("has no frames");
  if (first < 0) throw CaptureError(describe("cannot decode the first frame of", first));
  if (!setUpConverter(*decoded)) fail("has a pixel format that cannot be converted to BGR");
  haveDecoded = true;
  firstTimestamp = timestampOf(*decoded);
  lastTimestamp = firstTimestamp - period;
  if (onePicture) {
    still.create(size, CV_8UC3);
    if (!convert(still)) fail("has a pixel format that cannot be converted to BGR");
    // The demuxer and decoder have nothing more to give.
    packet.reset();
    decoded.reset();
    codec.reset();
    format.reset();
  }
}

int FileSource::Impl::decodeNext() {
  while (true) {
    const int received = avcodec_receive_frame(codec.get(), decoded.get());
    if (received == 0) return 1;
    if (received == AVERROR_EOF || drainFailed) return 0;
    if (received != AVERROR(EAGAIN)) {
      // Reported once; a decoder that fails while flushing is not asked again (it would answer
      // the same for ever).
      drainFailed = draining;
      return received;
    }
    if (draining) return 0;  // a decoder that says EAGAIN after the flush has nothing more
    const int read = av_read_frame(format.get(), packet.get());
    if (read < 0) {
      // The end, or a demuxer that cannot go on (truncated file, I/O error): either way, flush
      // what the decoder still holds. The error is reported once.
      draining = true;
      avcodec_send_packet(codec.get(), nullptr);
      if (read == AVERROR_EOF) continue;
      return read;
    }
    if (packet->stream_index != streamIndex) {
      av_packet_unref(packet.get());
      continue;
    }
    const int sent = avcodec_send_packet(codec.get(), packet.get());
    av_packet_unref(packet.get());
    // The packet is consumed even when it does not decode, so the next call moves on.
    if (sent < 0) return sent;
  }
}

bool FileSource::Impl::restart() {
  const AVStream* stream = format->streams[streamIndex];
  const std::int64_t start = stream->start_time == AV_NOPTS_VALUE ? 0 : stream->start_time;
  if (const int error = av_seek_frame(format.get(), streamIndex, start, AVSEEK_FLAG_BACKWARD);
      error < 0) {
    lastError = describe("cannot seek back to the start of", error);
    return false;
  }
  avcodec_flush_buffers(codec.get());
  draining = false;
  drainFailed = false;
  loopOffset += loopShift(firstTimestamp, lastTimestamp, period);
  lastTimestamp = firstTimestamp - period;
  return true;
}

Timestamp FileSource::Impl::timestampOf(const AVFrame& frame) const {
  const std::int64_t pts = frame.best_effort_timestamp;
  // Untimed frames (some raw streams) are placed one period after the previous one.
  if (pts == AV_NOPTS_VALUE) return lastTimestamp + period;
  return Timestamp(av_rescale_q(pts, timeBase, kNanoseconds));
}

bool FileSource::Impl::setUpConverter(const AVFrame& frame) {
  const auto pixelFormat = static_cast<AVPixelFormat>(frame.format);
  if (pixelFormat != swsFormat) {
    // Built once at start; again only if the stream changes its pixel format.
    sws.reset(sws_getContext(size.width, size.height, pixelFormat, size.width, size.height,
                             AV_PIX_FMT_BGR24, kSwsFlags, nullptr, nullptr, nullptr));
    swsFormat = sws ? pixelFormat : AV_PIX_FMT_NONE;
    if (!sws) return false;
    int* inverse = nullptr;
    int* table = nullptr;
    int targetRange = 0, brightness = 0, contrast = 0, saturation = 0;
    sws_getColorspaceDetails(sws.get(), &inverse, &swsDefaultRange, &table, &targetRange,
                             &brightness, &contrast, &saturation);
    swsColorspace = AVCOL_SPC_NB;  // forces the set-up below
  }
  if (frame.colorspace == swsColorspace && frame.color_range == swsRange) return true;
  swsColorspace = frame.colorspace;
  swsRange = frame.color_range;
  // An untagged range keeps swscale's guess for the format: full for JPEG-style yuvj and for gray,
  // limited for other YUV. RGB sources ignore it.
  const int sourceRange = swsRange == AVCOL_RANGE_JPEG   ? 1
                          : swsRange == AVCOL_RANGE_MPEG ? 0
                                                         : swsDefaultRange;
  const int* matrix = sws_getCoefficients(swsColorspaceOf(swsColorspace));
  sws_setColorspaceDetails(sws.get(), matrix, sourceRange, sws_getCoefficients(SWS_CS_DEFAULT), 1,
                           0, 1 << 16, 1 << 16);
  return true;
}

bool FileSource::Impl::convert(cv::Mat& out) {
  if (decoded->width != size.width || decoded->height != size.height) {
    lastError =
        fmt::format("camera '{}': frame {} of '{}' is {}x{}, but the stream started at {}x{}",
                    camera, framesRead, settings.path.string(), decoded->width, decoded->height,
                    size.width, size.height);
    return false;
  }
  if (!setUpConverter(*decoded)) {
    const char* name = av_get_pix_fmt_name(static_cast<AVPixelFormat>(decoded->format));
    lastError = fmt::format(
        "camera '{}': frame {} of '{}' has pixel format {}, which cannot be "
        "converted to BGR",
        camera, framesRead, settings.path.string(), name != nullptr ? name : "(unknown)");
    return false;
  }
  // Straight into the caller's buffer: no copy and no allocation per frame.
  std::uint8_t* target[] = {out.data};
  const int targetStride[] = {static_cast<int>(out.step[0])};
  sws_scale(sws.get(), decoded->data, decoded->linesize, 0, size.height, target, targetStride);
  return true;
}

ReadStatus FileSource::Impl::fault(std::string message) {
  lastError = std::move(message);
  return ReadStatus::kFault;
}

std::uint64_t FileSource::Impl::countFrames(const AVStream& stream) const {
  if (onePicture) return 1;
  if (stream.nb_frames > 0) return static_cast<std::uint64_t>(stream.nb_frames);
  // image2 counts a pattern's files in its duration; containers without a frame count (Matroska)
  // state a duration, the stream's or the whole file's.
  double seconds = 0;
  if (stream.duration != AV_NOPTS_VALUE && stream.duration > 0) {
    seconds = static_cast<double>(stream.duration) * av_q2d(stream.time_base);
  } else if (format->duration != AV_NOPTS_VALUE && format->duration > 0) {
    seconds = static_cast<double>(format->duration) / AV_TIME_BASE;
  }
  return static_cast<std::uint64_t>(
      std::llround(seconds * 1e9 / static_cast<double>(period.count())));
}

bool isStillPicturePath(const std::filesystem::path& path) {
  if (classifyFileName(path.string()) != FileNameKind::kPlainFile) return false;
  std::string extension = path.extension().string();
  std::ranges::transform(extension, extension.begin(),
                         [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  constexpr std::array<std::string_view, 9> kPictures{".png",  ".jpg",  ".jpeg", ".bmp", ".tif",
                                                      ".tiff", ".webp", ".ppm",  ".pgm"};
  return std::ranges::find(kPictures, extension) != kPictures.end();
}

cv::Mat readPicture(const std::filesystem::path& path) {
  FileSource source(path.filename().string(), {path, 30.0, false, Pacing::kAsFastAsPossible});
  Frame frame;
  frame.image.create(source.frameSize(), CV_8UC3);
  if (source.read(frame) != ReadStatus::kFrame) {
    throw CaptureError(fmt::format("{}: no picture in it: {}", path.string(), source.lastError()));
  }
  return frame.image;
}

FileSource::FileSource(std::string cameraName, FileSourceSettings settings,
                       std::shared_ptr<ReplayStart> start)
    : impl_(std::make_unique<Impl>()) {
  impl_->camera = std::move(cameraName);
  impl_->settings = std::move(settings);
  impl_->pacer = ReplayPacer(impl_->settings.pacing, std::move(start));
  impl_->open();
}

FileSource::~FileSource() = default;

cv::Size FileSource::frameSize() const { return impl_->size; }

Timestamp FileSource::nominalPeriod() const { return impl_->period; }

const std::string& FileSource::lastError() const { return impl_->lastError; }

bool FileSource::repeatsOnePicture() const { return impl_->onePicture && impl_->settings.loop; }

std::uint64_t FileSource::frameCountHint() const { return impl_->frameCountHint; }

ReadStatus FileSource::read(Frame& out) {
  auto& s = *impl_;
  if (s.onePicture) {
    if (s.framesRead > 0 && !s.settings.loop) return ReadStatus::kEndOfStream;
    // A copy of the picture decoded at start (about 1 ms for 1080p): the frame is handed down the
    // pipeline and back to the pool, while decoding the file again would cost a PNG decode each.
    s.still.copyTo(out.image);
    out.timestamp = s.firstTimestamp + static_cast<std::int64_t>(s.framesRead) * s.period;
    out.sequence = s.framesRead++;
    s.pacer.waitFor(out.timestamp);
    return ReadStatus::kFrame;
  }
  if (!s.haveDecoded) {
    int status = s.decodeNext();
    // A fresh pass that yields nothing (an unseekable or empty file) ends instead of looping.
    if (status == 0 && s.settings.loop && s.framesRead > 0 && s.restart()) status = s.decodeNext();
    if (status == 0) return ReadStatus::kEndOfStream;
    if (status < 0) {
      return s.fault(s.describe(fmt::format("decode error at frame {} of", s.framesRead), status));
    }
  }
  s.haveDecoded = false;
  if (out.image.size() != s.size || out.image.type() != CV_8UC3) {
    // The caller's pool should match frameSize(); rather than write out of bounds, fix it once.
    out.image.create(s.size, CV_8UC3);
  }
  if (!s.convert(out.image)) return s.fault(s.lastError);
  const std::string errors = concealedErrorsOf(*s.decoded);
  out.concealedErrors = !errors.empty();
  if (out.concealedErrors) {
    s.lastError = fmt::format("camera '{}': frame {} of '{}' was decoded with errors ({})",
                              s.camera, s.framesRead, s.settings.path.string(), errors);
  }
  const Timestamp fileTimestamp = s.timestampOf(*s.decoded);
  s.lastTimestamp = std::max(s.lastTimestamp, fileTimestamp);
  out.timestamp = fileTimestamp + s.loopOffset;
  out.sequence = s.framesRead++;
  s.pacer.waitFor(out.timestamp);
  return ReadStatus::kFrame;
}

}  // namespace surroundd::capture
