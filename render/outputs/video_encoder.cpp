#include "render/outputs/video_encoder.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "common/ffmpeg_util.hpp"
#include "render/outputs/capture_time_sei.hpp"
#include "render/outputs/encoder_conversion.hpp"

extern "C" {
#include <libavutil/hwcontext.h>
#include <libavutil/opt.h>
#include <libavutil/pixdesc.h>
}

namespace surroundd::render {
namespace {

// Encoder time base: microseconds, so that timestamps keep their precision in MP4. Matroska stores
// milliseconds whatever is asked (its muxer forces 1/1000 on the stream); packets are rescaled.
constexpr AVRational kMicroseconds{1, 1'000'000};
// MP4 writes a first timestamp other than zero as an edit list in the movie timescale, which
// defaults to milliseconds: the whole file would then be shifted by up to 1 ms.
constexpr const char* kMp4MovieTimescale = "1000000";
constexpr const char* kMp4FragmentMicroseconds = "1000000";
// A few seconds of a 1080p stream.
constexpr std::uintmax_t kMinFreeBytes = std::uintmax_t{8} << 20;

// The video packets a player reads from `file` before it ends or breaks off: 0 when it does not
// open as a video at all (an MP4 cut before its first fragment's index).
std::size_t framesIn(const std::filesystem::path& file) {
  const ffmpeg::ExpectedFailures quiet;  // a file cut short is what is being measured
  AVFormatContext* raw = nullptr;
  if (avformat_open_input(&raw, file.c_str(), nullptr, nullptr) < 0) return 0;
  const ffmpeg::InputFormatPtr input(raw);
  if (avformat_find_stream_info(input.get(), nullptr) < 0) return 0;
  const int video = av_find_best_stream(input.get(), AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
  if (video < 0) return 0;
  const ffmpeg::PacketPtr packet(av_packet_alloc());
  std::size_t frames = 0;
  while (packet && av_read_frame(input.get(), packet.get()) >= 0) {
    if (packet->stream_index == video && (packet->flags & AV_PKT_FLAG_CORRUPT) == 0) ++frames;
    av_packet_unref(packet.get());
  }
  return frames;
}

bool takes(const AVCodec* encoder, AVPixelFormat format) {
  // An encoder that lists none (v4l2m2m) learns its device's formats only when it opens.
  if (encoder->pix_fmts == nullptr) return format == AV_PIX_FMT_YUV420P;
  for (const AVPixelFormat* f = encoder->pix_fmts; *f != AV_PIX_FMT_NONE; ++f) {
    if (*f == format) return true;
  }
  return false;
}

}  // namespace

std::optional<std::string> h264EncoderProblem(std::string_view name) {
  if (name == "auto") return std::nullopt;
  const AVCodec* encoder = avcodec_find_encoder_by_name(std::string(name).c_str());
  if (encoder == nullptr) return fmt::format("this FFmpeg has no encoder '{}'", name);
  if (encoder->id != AV_CODEC_ID_H264) return fmt::format("'{}' does not encode H.264", name);
  return std::nullopt;
}

struct VideoEncoder::Impl {
  VideoEncoderSettings settings;
  std::filesystem::path partPath;
  ffmpeg::OutputFormatPtr format;
  ffmpeg::CodecContextPtr codec;
  ffmpeg::FramePtr frame;
  ffmpeg::PacketPtr packet;
  std::optional<EncoderConversion> conversion;    // each picture into `frame`
  AVPixelFormat pictureFormat = AV_PIX_FMT_NONE;  // `frame`'s
  ffmpeg::BufferPtr hwDevice;  // a VA-API encoder's device and frame pool; null for the others
  ffmpeg::BufferPtr hwFrames;
  ffmpeg::FramePtr hwFrame;
  AVStream* stream = nullptr;     // owned by `format`; null when pictures are handed over
  EncodedPictureHandler handler;  // where the pictures go instead of a container, if set
  // Set by any thread (a viewer joining), taken by the one that writes.
  std::atomic<bool> keyframeWanted{false};
  std::uint64_t framesWritten = 0;
  std::uint64_t packetsWritten = 0;  // into the file, as far as the muxer was concerned
  std::optional<std::int64_t> lastPts;
  bool closed = false;

  bool handedOver() const { return static_cast<bool>(handler); }
  // A stream a viewer watches live (MPEG-TS over UDP, or handed to a server), not a file.
  bool live() const { return !settings.url.empty() || handedOver(); }
  std::string target() const { return live() ? settings.url : settings.path.string(); }

  const char* kind() const { return live() ? "stream" : "video"; }

  [[noreturn]] void fail(std::string_view what, int error = 0) const {
    throw EncoderError(error == 0 ? fmt::format("{} '{}': {}", kind(), target(), what)
                                  : fmt::format("{} '{}': {}: {}", kind(), target(), what,
                                                ffmpeg::errorText(error)));
  }

  void open();
  void openContainer();
  // A file is not begun on a disk that is all but full: it would fail at its first writes.
  void refuseAFullDisk() const;
  void openCodec(AVPixelFormat pixelFormat);
  // Empty when `encoder` opened; else why not (and nothing of it kept).
  std::string tryCodec(const AVCodec* encoder, AVPixelFormat pixelFormat);
  std::string useHardwareFrames();
  void drain(bool flushing);
  void handOver(const AVPacket& encoded) const;
  // After a failure (a full disk, a failed encode): closes the file where it stands and gives it
  // its name, or removes it when no packet reached it. Says which, for the error message.
  std::string endFile();
  // Fails as fail() does; a file is ended first (endFile()) and the encoder writes no more.
  [[noreturn]] void failAndEndFile(std::string_view what, int error) {
    if (live()) fail(what, error);
    closed = true;
    const std::string ended = endFile();
    fail(fmt::format("{}: {}; {}", what, ffmpeg::errorText(error), ended));
  }
};

void VideoEncoder::Impl::open() {
  if (settings.size.width <= 0 || settings.size.height <= 0 || settings.size.width % 2 != 0 ||
      settings.size.height % 2 != 0) {
    fail(fmt::format("frame size must be even and positive, got {}x{}", settings.size.width,
                     settings.size.height));
  }
  const AVPixelFormat pixelFormat = av_get_pix_fmt(settings.pixelFormat.c_str());
  if (pixelFormat != AV_PIX_FMT_YUV420P && pixelFormat != AV_PIX_FMT_YUV444P &&
      pixelFormat != AV_PIX_FMT_BGR24) {
    fail(fmt::format("pixel format must be yuv420p, yuv444p or bgr24, got '{}'",
                     settings.pixelFormat));
  }
  if (!(settings.nominalFps > 0 && settings.nominalFps <= 1000)) {
    fail(fmt::format("nominal frame rate must be in (0, 1000], got {}", settings.nominalFps));
  }
  if (settings.crf < 0 || settings.crf > 51) {
    fail(fmt::format("crf must be in 0..51 (0 = lossless), got {}", settings.crf));
  }
  if (!handedOver()) openContainer();
  openCodec(pixelFormat);
  if (!handedOver()) {
    stream = avformat_new_stream(format.get(), nullptr);
    if (stream == nullptr) fail("cannot add a video stream");
    stream->time_base = kMicroseconds;
    stream->avg_frame_rate = codec->framerate;
    stream->r_frame_rate = codec->framerate;
    if (const int error = avcodec_parameters_from_context(stream->codecpar, codec.get());
        error < 0) {
      fail("cannot describe the video stream", error);
    }
    AVDictionary* muxerOptions = nullptr;
    if (settings.path.extension() == ".mp4" && settings.url.empty()) {
      av_dict_set(&muxerOptions, "movie_timescale", kMp4MovieTimescale, 0);
      // Fragments of at most a second, each playable alone: a file cut short (a full disk, a
      // kill, a power loss) plays up to its last whole fragment, where a plain MP4 keeps its
      // index for the end and plays nothing. The index is written with the first fragment
      // (delay_moov), when the stream's start is known, so that timestamps stay as given.
      av_dict_set(&muxerOptions, "movflags", "+frag_keyframe+delay_moov+default_base_moof", 0);
      av_dict_set(&muxerOptions, "frag_duration", kMp4FragmentMicroseconds, 0);
    }
    if (!settings.url.empty()) {
      // Each picture leaves whole as soon as it is encoded: its last datagram is not held for the
      // next picture's, and its PES says how long it is, so that a receiver need not wait for
      // the next one to know it has it all.
      av_dict_set(&muxerOptions, "flush_packets", "1", 0);
      av_dict_set(&muxerOptions, "omit_video_pes_length", "0", 0);
    }
    const int headerError = avformat_write_header(format.get(), &muxerOptions);
    av_dict_free(&muxerOptions);
    if (headerError < 0) fail("cannot write the container header", headerError);
  }

  frame.reset(av_frame_alloc());
  packet.reset(av_packet_alloc());
  if (!frame || !packet) fail("out of memory");
  frame->format = pictureFormat;
  frame->width = settings.size.width;
  frame->height = settings.size.height;
  if (const int error = av_frame_get_buffer(frame.get(), 0); error < 0)
    fail("out of memory", error);
  try {
    conversion.emplace(settings.size, pictureFormat);
  } catch (const std::runtime_error& e) {
    fail(e.what());
  }
  if (hwFrames) {
    hwFrame.reset(av_frame_alloc());
    if (!hwFrame) fail("out of memory");
  }
}

void VideoEncoder::Impl::openContainer() {
  const auto extension = settings.path.extension().string();
  const bool network = !settings.url.empty();
  const char* muxer = network               ? "mpegts"
                      : extension == ".mp4" ? "mp4"
                      : extension == ".mkv" ? "matroska"
                                            : nullptr;
  if (muxer == nullptr)
    fail(fmt::format("expected a file ending in .mp4 or .mkv, got '{}'", extension));
  if (network && !settings.url.starts_with("udp://")) fail("expected a udp://HOST:PORT address");
  // A file is written under a temporary name until it is finalized; a stream has no name to keep.
  std::string destination = settings.url;
  if (!network) {
    refuseAFullDisk();
    partPath = settings.path;
    partPath += ".part";
    destination = partPath.string();
  } else if (destination.find("pkt_size=") == std::string::npos) {
    // Seven 188-byte TS packets per datagram: below every Ethernet MTU, so nothing is fragmented.
    destination += destination.find('?') == std::string::npos ? "?pkt_size=1316" : "&pkt_size=1316";
  }
  AVFormatContext* rawFormat = nullptr;
  if (const int error =
          avformat_alloc_output_context2(&rawFormat, nullptr, muxer, destination.c_str());
      error < 0) {
    fail("cannot set up the container", error);
  }
  format.reset(rawFormat);
  if (settings.bitExact) format->flags |= AVFMT_FLAG_BITEXACT;
  if (const int error = avio_open(&format->pb, destination.c_str(), AVIO_FLAG_WRITE); error < 0) {
    fail(network ? std::string("cannot open") : fmt::format("cannot create '{}'", destination),
         error);
  }
}

void VideoEncoder::Impl::refuseAFullDisk() const {
  const auto folder = settings.path.parent_path().empty() ? std::filesystem::path(".")
                                                          : settings.path.parent_path();
  std::error_code error;
  const std::filesystem::space_info space = std::filesystem::space(folder, error);
  // A folder that cannot be asked is left to the file's creation to name what is wrong.
  if (!error && space.available < kMinFreeBytes) {
    fail(
        fmt::format("the disk is full: {} KiB free in '{}', less than the {} MiB a video starts "
                    "with",
                    space.available >> 10, folder.string(), kMinFreeBytes >> 20));
  }
}

void VideoEncoder::Impl::openCodec(AVPixelFormat pixelFormat) {
  const std::string& wanted = settings.encoder;
  // bgr24 is H.264 on the pictures' own channels (libx264rgb): with crf 0 the frames come back
  // bit for bit.
  const bool rgb = pixelFormat == AV_PIX_FMT_BGR24;
  const bool x264Only = rgb || settings.bitExact;
  if (x264Only && wanted != "libx264" && wanted != "auto") {
    fail(fmt::format("{} needs libx264, not {}", rgb ? "pixel format bgr24" : "bit-exact output",
                     wanted));
  }
  if (x264Only || wanted == "libx264" || wanted == "auto") {
    // What only x264 does, or the fallback after the hardware encoders.
    std::vector<std::string> notOpened;
    if (!x264Only && wanted == "auto") {
      const ffmpeg::ExpectedFailures expected;  // said in one line below, not as FFmpeg's errors
      for (const char* name : kHardwareH264Encoders) {
        const AVCodec* encoder = avcodec_find_encoder_by_name(name);
        std::string why = encoder ? tryCodec(encoder, pixelFormat) : "not in this FFmpeg";
        if (why.empty()) {
          spdlog::info("{} '{}': H.264 by {}", kind(), target(), name);
          return;
        }
        notOpened.push_back(fmt::format("{}: {}", name, why));
      }
    }
    const char* name = rgb ? "libx264rgb" : "libx264";
    const AVCodec* encoder = avcodec_find_encoder_by_name(name);
    if (encoder == nullptr) fail(fmt::format("this FFmpeg has no {} encoder", name));
    if (std::string why = tryCodec(encoder, pixelFormat); !why.empty()) fail(why);
    if (!notOpened.empty()) {
      spdlog::info("{} '{}': H.264 by {}, as no hardware encoder opens here ({})", kind(), target(),
                   name, fmt::join(notOpened, "; "));
    }
    return;
  }
  if (const auto problem = h264EncoderProblem(wanted)) fail(*problem);
  if (std::string why = tryCodec(avcodec_find_encoder_by_name(wanted.c_str()), pixelFormat);
      !why.empty()) {
    fail(why);
  }
}

std::string VideoEncoder::Impl::tryCodec(const AVCodec* encoder, AVPixelFormat pixelFormat) {
  const bool x264 = std::string_view(encoder->name).starts_with("libx264");
  codec.reset(avcodec_alloc_context3(encoder));
  if (!codec) fail("out of memory");
  codec->width = settings.size.width;
  codec->height = settings.size.height;
  codec->time_base = kMicroseconds;
  // A large bound keeps NTSC rates exact (29.97 -> 30000/1001).
  codec->framerate = av_d2q(settings.nominalFps, 1 << 16);
  codec->thread_count = settings.threads;
  // BT.601 limited range, tagged, so that every decoder converts back the way sws converted here.
  const bool rgb = pixelFormat == AV_PIX_FMT_BGR24;
  codec->colorspace = rgb ? AVCOL_SPC_RGB : AVCOL_SPC_SMPTE170M;
  codec->color_primaries = AVCOL_PRI_SMPTE170M;
  codec->color_trc = AVCOL_TRC_SMPTE170M;
  codec->color_range = rgb ? AVCOL_RANGE_JPEG : AVCOL_RANGE_MPEG;
  if (settings.bitExact) codec->flags |= AV_CODEC_FLAG_BITEXACT;
  // Handed-over pictures carry their parameter sets in the stream, before each keyframe.
  if (format && (format->oformat->flags & AVFMT_GLOBALHEADER) != 0)
    codec->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  const std::string crf = std::to_string(settings.crf);
  if (live()) {
    // A viewer sees each picture as soon as it is encoded (no look-ahead, no B-frames), and one
    // that joins late waits at most a second for a keyframe.
    codec->gop_size = std::max(1, static_cast<int>(std::lround(settings.nominalFps)));
    codec->max_b_frames = 0;
  }
  pictureFormat = pixelFormat;
  if (x264) {
    codec->pix_fmt = pixelFormat;
    av_opt_set(codec->priv_data, "preset", settings.preset.c_str(), 0);
    av_opt_set(codec->priv_data, "crf", crf.c_str(), 0);
    // x264's AVX-512 macroblock-tree kernel makes the output depend on leftover heap contents
    // (seen with x264 164 r3095); without mbtree the same input gives the same bytes on every CPU.
    if (settings.bitExact) av_opt_set(codec->priv_data, "x264-params", "mbtree=0", 0);
    if (pixelFormat == AV_PIX_FMT_YUV444P) av_opt_set(codec->priv_data, "profile", "high444", 0);
    if (live()) av_opt_set(codec->priv_data, "tune", "zerolatency", 0);
    // A forced keyframe is an IDR picture, where a viewer that joins can start.
    av_opt_set(codec->priv_data, "forced-idr", "1", 0);
  } else {
    if (takes(encoder, pixelFormat)) {
      codec->pix_fmt = pixelFormat;
    } else if (pixelFormat == AV_PIX_FMT_YUV420P && takes(encoder, AV_PIX_FMT_NV12)) {
      codec->pix_fmt = pictureFormat = AV_PIX_FMT_NV12;  // the same 4:2:0 samples, interleaved
    } else if (pixelFormat == AV_PIX_FMT_YUV420P && takes(encoder, AV_PIX_FMT_VAAPI)) {
      if (std::string why = useHardwareFrames(); !why.empty()) {
        codec.reset();
        return why;
      }
    } else {
      codec.reset();
      return fmt::format("takes no {} pictures", settings.pixelFormat);
    }
    // Constant quality where the encoder has it (the option is ignored where it does not), and a
    // bit rate for those that only follow one.
    av_opt_set(codec->priv_data, "rc", "vbr", 0);  // nvenc
    av_opt_set(codec->priv_data, "cq", crf.c_str(), 0);
    av_opt_set(codec->priv_data, "rc_mode", "CQP", 0);  // vaapi
    av_opt_set(codec->priv_data, "qp", crf.c_str(), 0);
    codec->bit_rate = static_cast<std::int64_t>(0.1 * settings.size.area() * settings.nominalFps);
    if (live()) av_opt_set(codec->priv_data, "zerolatency", "1", 0);  // nvenc
    av_opt_set(codec->priv_data, "forced-idr", "1", 0);               // nvenc
  }
  // Capture times go into SEI messages only when asked for (libx264, nvenc).
  if (settings.stampCaptureTime) av_opt_set(codec->priv_data, "udu_sei", "1", 0);
  // x264 checks the preset only here; a hardware encoder finds its device here.
  if (const int error = avcodec_open2(codec.get(), encoder, nullptr); error < 0) {
    codec.reset();
    hwFrames.reset();
    hwDevice.reset();
    return x264 ? fmt::format("cannot open the H.264 encoder (preset '{}', crf {}, {}): {}",
                              settings.preset, settings.crf, settings.pixelFormat,
                              ffmpeg::errorText(error))
                : fmt::format("cannot open {}: {}", encoder->name, ffmpeg::errorText(error));
  }
  return {};
}

std::string VideoEncoder::Impl::useHardwareFrames() {
  AVBufferRef* device = nullptr;
  if (const int error =
          av_hwdevice_ctx_create(&device, AV_HWDEVICE_TYPE_VAAPI, nullptr, nullptr, 0);
      error < 0) {
    return fmt::format("no VA-API device: {}", ffmpeg::errorText(error));
  }
  hwDevice.reset(device);
  hwFrames.reset(av_hwframe_ctx_alloc(device));
  if (!hwFrames) fail("out of memory");
  auto* frames = reinterpret_cast<AVHWFramesContext*>(hwFrames->data);
  frames->format = AV_PIX_FMT_VAAPI;
  frames->sw_format = AV_PIX_FMT_NV12;
  frames->width = settings.size.width;
  frames->height = settings.size.height;
  frames->initial_pool_size = 4;
  if (const int error = av_hwframe_ctx_init(hwFrames.get()); error < 0) {
    hwFrames.reset();
    hwDevice.reset();
    return fmt::format("cannot make VA-API frames: {}", ffmpeg::errorText(error));
  }
  codec->pix_fmt = AV_PIX_FMT_VAAPI;
  codec->hw_frames_ctx = av_buffer_ref(hwFrames.get());
  pictureFormat = AV_PIX_FMT_NV12;
  return {};
}

void VideoEncoder::Impl::drain(bool flushing) {
  while (true) {
    const int status = avcodec_receive_packet(codec.get(), packet.get());
    if (status == AVERROR(EAGAIN) || (flushing && status == AVERROR_EOF)) return;
    if (status < 0) failAndEndFile("encoding failed", status);
    if (handedOver()) {
      handOver(*packet);
      av_packet_unref(packet.get());
      continue;
    }
    av_packet_rescale_ts(packet.get(), codec->time_base, stream->time_base);
    packet->stream_index = stream->index;
    // A full disk: what reached the file stays, playable, and this encoder writes no more.
    if (const int error = av_interleaved_write_frame(format.get(), packet.get()); error < 0) {
      failAndEndFile(live() ? "cannot send" : "cannot write to the file", error);
    }
    ++packetsWritten;
  }
}

std::string VideoEncoder::Impl::endFile() {
  format.reset();  // closes the file; what its buffer still held may not reach the disk
  // What reached the disk, read back: packets the muxer took may still have been in its buffer,
  // or in an MP4 fragment whose index was never written.
  const std::size_t kept = packetsWritten == 0 ? 0 : framesIn(partPath);
  std::error_code error;
  if (kept == 0) {
    std::filesystem::remove(partPath, error);
    return framesWritten == 0 ? "no file made"
                              : fmt::format(
                                    "none of the {} frames encoded reached the file; no "
                                    "file kept",
                                    framesWritten);
  }
  std::filesystem::rename(partPath, settings.path, error);
  if (error) {
    return fmt::format("'{}' keeps the first {} of {} frames encoded, under that name ({})",
                       partPath.string(), kept, framesWritten, error.message());
  }
  return fmt::format("'{}' keeps the first {} of {} frames encoded, playable",
                     settings.path.string(), kept, framesWritten);
}

void VideoEncoder::Impl::handOver(const AVPacket& encoded) const {
  EncodedPicture picture;
  picture.bytes = {encoded.data, static_cast<std::size_t>(encoded.size)};
  picture.timestamp = std::chrono::microseconds(encoded.pts);  // the codec's time base
  picture.keyframe = (encoded.flags & AV_PKT_FLAG_KEY) != 0;
  handler(picture);
}

VideoEncoder::VideoEncoder(VideoEncoderSettings settings)
    : VideoEncoder(std::move(settings), nullptr) {}

VideoEncoder::VideoEncoder(VideoEncoderSettings settings, EncodedPictureHandler handler)
    : impl_(std::make_unique<Impl>()) {
  impl_->settings = std::move(settings);
  impl_->handler = std::move(handler);
  try {
    impl_->open();
  } catch (...) {
    // Nothing half-made stays behind.
    impl_->format.reset();
    if (!impl_->partPath.empty()) {
      std::error_code ignored;
      std::filesystem::remove(impl_->partPath, ignored);
    }
    throw;
  }
}

VideoEncoder::~VideoEncoder() {
  try {
    close();
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
  }
}

void VideoEncoder::write(const cv::Mat& picture, std::chrono::nanoseconds timestamp,
                         std::optional<std::chrono::system_clock::time_point> captured) {
  auto& s = *impl_;
  if (s.closed) s.fail("write after close");
  const std::int64_t pts = std::chrono::duration_cast<std::chrono::microseconds>(timestamp).count();
  // The container keeps its own precision (ms in MKV): two frames must not fall on one tick there.
  const AVRational precision = s.stream != nullptr ? s.stream->time_base : kMicroseconds;
  const std::int64_t containerPts = av_rescale_q(pts, kMicroseconds, precision);
  if (s.lastPts && containerPts <= av_rescale_q(*s.lastPts, kMicroseconds, precision)) {
    s.fail(fmt::format("timestamps must increase (at the file's precision): {} us after {} us", pts,
                       *s.lastPts));
  }
  if (const int error = av_frame_make_writable(s.frame.get()); error < 0)
    s.fail("out of memory", error);
  if (!s.conversion->convert(picture, *s.frame)) {
    s.fail(fmt::format("expected an 8-bit BGR{} picture of {}x{}, got {}x{} of type {}",
                       s.conversion->takesI420() ? " or I420" : "", s.settings.size.width,
                       s.settings.size.height, picture.cols, picture.rows, picture.type()));
  }
  s.frame->pts = pts;
  AVFrame* encoded = s.frame.get();
  if (s.hwFrames) {
    // Into one of the device's frames (from its pool): the encoder reads only those.
    if (const int error = av_hwframe_get_buffer(s.hwFrames.get(), s.hwFrame.get(), 0); error < 0)
      s.fail("no VA-API frame to encode into", error);
    if (const int error = av_hwframe_transfer_data(s.hwFrame.get(), s.frame.get(), 0); error < 0)
      s.fail("cannot upload the picture to the VA-API device", error);
    s.hwFrame->pts = pts;
    encoded = s.hwFrame.get();
  }
  encoded->pict_type = s.keyframeWanted.exchange(false) ? AV_PICTURE_TYPE_I : AV_PICTURE_TYPE_NONE;
  if (s.settings.stampCaptureTime && captured) {
    const CaptureTimeSei payload = captureTimeSei(*captured);
    AVFrameSideData* sei =
        av_frame_new_side_data(encoded, AV_FRAME_DATA_SEI_UNREGISTERED, payload.size());
    if (sei == nullptr) s.fail("out of memory");
    std::copy(payload.begin(), payload.end(), sei->data);
  }
  const int sent = avcodec_send_frame(s.codec.get(), encoded);
  // The frame is used again for the next picture: its capture time must not stay with it.
  av_frame_remove_side_data(encoded, AV_FRAME_DATA_SEI_UNREGISTERED);
  if (s.hwFrames) av_frame_unref(s.hwFrame.get());
  if (sent < 0) s.fail("encoding failed", sent);
  s.drain(false);
  s.lastPts = pts;
  ++s.framesWritten;
}

void VideoEncoder::close() {
  auto& s = *impl_;
  if (s.closed || (!s.format && !s.handedOver())) return;
  s.closed = true;
  if (s.framesWritten == 0) {
    s.format.reset();
    if (s.live()) return;  // nothing was sent; nothing is lost
    s.endFile();
    s.fail("no frames written; no file made");
  }
  if (const int error = avcodec_send_frame(s.codec.get(), nullptr); error < 0) {
    s.failAndEndFile("flushing failed", error);
  }
  s.drain(true);
  if (s.handedOver()) return;
  if (const int error = av_write_trailer(s.format.get()); error < 0) {
    s.failAndEndFile(s.live() ? "cannot finish the stream" : "cannot finalize the file", error);
  }
  s.format.reset();  // closes the file
  if (s.live()) return;
  std::error_code renamed;
  std::filesystem::rename(s.partPath, s.settings.path, renamed);
  // The finished file is kept under its .part name rather than lost.
  if (renamed) {
    s.fail(fmt::format("finished, but cannot rename '{}' to the final name: {}",
                       s.partPath.string(), renamed.message()));
  }
}

const std::filesystem::path& VideoEncoder::path() const { return impl_->settings.path; }

std::string VideoEncoder::target() const { return impl_->target(); }

std::uint64_t VideoEncoder::framesWritten() const { return impl_->framesWritten; }

void VideoEncoder::requestKeyframe() { impl_->keyframeWanted = true; }

std::string VideoEncoder::encoderName() const { return impl_->codec->codec->name; }

bool VideoEncoder::takesI420() const { return impl_->conversion->takesI420(); }

}  // namespace surroundd::render
