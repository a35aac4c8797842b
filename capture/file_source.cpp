#include "capture/file_source.hpp"

#include <optional>
#include <thread>

#include <fmt/format.h>

#include "common/ffmpeg_util.hpp"

namespace surroundd::capture {
namespace {

constexpr AVRational kNanoseconds{1, 1'000'000'000};

bool isImageSequence(const std::filesystem::path& path) {
  return path.string().find('%') != std::string::npos;
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

  bool haveDecoded = false;  // `decoded` holds a frame not yet returned (the one probed at start)
  bool draining = false;     // the demuxer is exhausted; the decoder is being flushed
  std::uint64_t framesRead = 0;
  Timestamp loopOffset{0};  // added to timestamps after each loop so they keep increasing
  Timestamp firstTimestamp{0};
  Timestamp lastTimestamp{0};
  std::optional<std::chrono::steady_clock::time_point> pacingStart;
  AVColorSpace swsColorspace = AVCOL_SPC_UNSPECIFIED;
  AVColorRange swsRange = AVCOL_RANGE_UNSPECIFIED;

  std::string describe(std::string_view what, int error) const {
    return fmt::format("camera '{}': {} '{}': {}", camera, what, settings.path.string(),
                       ffmpeg::errorText(error));
  }

  void open();
  // Decodes the next frame into `decoded`. 1: a frame, 0: end of stream, <0: an FFmpeg error.
  int decodeNext();
  bool restart();
  bool convert(Frame& out);
  Timestamp timestampOf(const AVFrame& frame) const;
};

void FileSource::Impl::open() {
  const bool sequence = isImageSequence(settings.path);
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
  if (streamIndex < 0 || decoder == nullptr) {
    throw CaptureError(fmt::format("camera '{}': '{}' has no video stream that can be decoded",
                                   camera, settings.path.string()));
  }
  const AVStream* stream = format->streams[streamIndex];
  timeBase = stream->time_base;
  codec.reset(avcodec_alloc_context3(decoder));
  avcodec_parameters_to_context(codec.get(), stream->codecpar);
  // One decoding thread: the pipeline already runs one capture thread per camera.
  codec->thread_count = 1;
  if (const int error = avcodec_open2(codec.get(), decoder, nullptr); error < 0) {
    throw CaptureError(describe("cannot open the decoder for", error));
  }
  size = {codec->width, codec->height};
  if (size.width <= 0 || size.height <= 0) {
    throw CaptureError(
        fmt::format("camera '{}': '{}' has no frame size", camera, settings.path.string()));
  }
  AVRational rate = stream->avg_frame_rate;
  if (rate.num <= 0 || rate.den <= 0) rate = stream->r_frame_rate;
  const double fps =
      sequence || rate.num <= 0 || rate.den <= 0 ? settings.sequenceFps : av_q2d(rate);
  period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / fps));
  packet.reset(av_packet_alloc());
  decoded.reset(av_frame_alloc());

  // Decode the first frame now: a file whose header parses but whose data does not fails at start.
  const int first = decodeNext();
  if (first <= 0) {
    throw CaptureError(
        first == 0 ? fmt::format("camera '{}': '{}' has no frames", camera, settings.path.string())
                   : describe("cannot decode the first frame of", first));
  }
  haveDecoded = true;
  firstTimestamp = timestampOf(*decoded);
}

int FileSource::Impl::decodeNext() {
  while (true) {
    const int received = avcodec_receive_frame(codec.get(), decoded.get());
    if (received == 0) return 1;
    if (received == AVERROR_EOF) return 0;
    if (received != AVERROR(EAGAIN)) return received;
    if (draining) return 0;
    const int read = av_read_frame(format.get(), packet.get());
    if (read == AVERROR_EOF) {
      draining = true;
      avcodec_send_packet(codec.get(), nullptr);
      continue;
    }
    if (read < 0) return read;
    if (packet->stream_index != streamIndex) {
      av_packet_unref(packet.get());
      continue;
    }
    const int sent = avcodec_send_packet(codec.get(), packet.get());
    av_packet_unref(packet.get());
    if (sent < 0 && sent != AVERROR(EAGAIN)) return sent;
  }
}

bool FileSource::Impl::restart() {
  if (av_seek_frame(format.get(), streamIndex,
                    format->streams[streamIndex]->start_time == AV_NOPTS_VALUE
                        ? 0
                        : format->streams[streamIndex]->start_time,
                    AVSEEK_FLAG_BACKWARD) < 0) {
    return false;
  }
  avcodec_flush_buffers(codec.get());
  draining = false;
  loopOffset += lastTimestamp + period - firstTimestamp;
  return true;
}

Timestamp FileSource::Impl::timestampOf(const AVFrame& frame) const {
  const std::int64_t pts = frame.best_effort_timestamp;
  if (pts == AV_NOPTS_VALUE) return firstTimestamp + static_cast<std::int64_t>(framesRead) * period;
  return Timestamp(av_rescale_q(pts, timeBase, kNanoseconds));
}

bool FileSource::Impl::convert(Frame& out) {
  if (decoded->width != size.width || decoded->height != size.height) {
    lastError = fmt::format("camera '{}': frame size changed to {}x{} in '{}' (expected {}x{})",
                            camera, decoded->width, decoded->height, settings.path.string(),
                            size.width, size.height);
    return false;
  }
  const auto pixelFormat = static_cast<AVPixelFormat>(decoded->format);
  // Built once for the stream's format; rebuilt only if the file changes it.
  sws.reset(sws_getCachedContext(sws.release(), size.width, size.height, pixelFormat, size.width,
                                 size.height, AV_PIX_FMT_BGR24,
                                 SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT, nullptr,
                                 nullptr, nullptr));
  if (!sws) {
    lastError = fmt::format("camera '{}': cannot convert pixel format {} of '{}'", camera,
                            static_cast<int>(pixelFormat), settings.path.string());
    return false;
  }
  if (decoded->colorspace != swsColorspace || decoded->color_range != swsRange) {
    swsColorspace = decoded->colorspace;
    swsRange = decoded->color_range;
    const int standard = swsColorspace == AVCOL_SPC_BT709 ? SWS_CS_ITU709 : SWS_CS_ITU601;
    sws_setColorspaceDetails(sws.get(), sws_getCoefficients(standard),
                             swsRange == AVCOL_RANGE_JPEG ? 1 : 0,
                             sws_getCoefficients(SWS_CS_DEFAULT), 1, 0, 1 << 16, 1 << 16);
  }
  std::uint8_t* target[] = {out.image.data};
  const int targetStride[] = {static_cast<int>(out.image.step[0])};
  sws_scale(sws.get(), decoded->data, decoded->linesize, 0, size.height, target, targetStride);
  return true;
}

FileSource::FileSource(std::string cameraName, FileSourceSettings settings)
    : impl_(std::make_unique<Impl>()) {
  impl_->camera = std::move(cameraName);
  impl_->settings = std::move(settings);
  impl_->open();
}

FileSource::~FileSource() = default;

cv::Size FileSource::frameSize() const { return impl_->size; }

Timestamp FileSource::nominalPeriod() const { return impl_->period; }

const std::string& FileSource::lastError() const { return impl_->lastError; }

ReadStatus FileSource::read(Frame& out) {
  auto& s = *impl_;
  if (!s.haveDecoded) {
    int status = s.decodeNext();
    if (status == 0 && s.settings.loop && s.framesRead > 0 && s.restart()) status = s.decodeNext();
    if (status == 0) return ReadStatus::kEndOfStream;
    if (status < 0) {
      s.lastError = s.describe(fmt::format("decoding frame {} failed in", s.framesRead), status);
      // A demuxer error that repeats would fault forever: skip to the end instead.
      if (status != AVERROR_INVALIDDATA) s.draining = true;
      return ReadStatus::kFault;
    }
  }
  s.haveDecoded = false;
  if (out.image.size() != s.size || out.image.type() != CV_8UC3) out.image.create(s.size, CV_8UC3);
  if (!s.convert(out)) return ReadStatus::kFault;
  out.timestamp = s.timestampOf(*s.decoded) + s.loopOffset;
  s.lastTimestamp = out.timestamp - s.loopOffset;
  ++s.framesRead;
  if (s.settings.pacing == Pacing::kRealtime) {
    const auto now = std::chrono::steady_clock::now();
    if (!s.pacingStart) s.pacingStart = now - (out.timestamp - s.firstTimestamp);
    std::this_thread::sleep_until(*s.pacingStart + (out.timestamp - s.firstTimestamp));
  }
  return ReadStatus::kFrame;
}

}  // namespace surroundd::capture
