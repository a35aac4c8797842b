#include "tools/bench/stream_viewer.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "common/ffmpeg_util.hpp"
#include "render/outputs/capture_time_sei.hpp"

namespace surroundd::bench {

struct StreamViewer::Impl {
  std::string url;
  ffmpeg::InputFormatPtr input;
  ffmpeg::CodecContextPtr codec;
  ffmpeg::PacketPtr packet{av_packet_alloc()};
  ffmpeg::FramePtr frame{av_frame_alloc()};
  SwsContext* sws = nullptr;  // sws_getCachedContext's: kept while the picture format holds
  int stream = -1;
  bool flushed = false;

  ~Impl() { sws_freeContext(sws); }

  void open(const StreamViewerSettings& settings);
  ViewedPicture convert();
};

void StreamViewer::Impl::open(const StreamViewerSettings& settings) {
  const auto timeout = std::chrono::microseconds(settings.timeout).count();
  AVDictionary* options = nullptr;
  // Pictures are handed on as soon as they are read, as a live player does.
  av_dict_set(&options, "fflags", "nobuffer", 0);
  const AVInputFormat* format = nullptr;
  std::string address = settings.url;
  if (settings.url.starts_with("rtsp://")) {
    if (settings.transport != "udp" && settings.transport != "tcp") {
      throw std::runtime_error(
          fmt::format("the RTSP transport must be udp or tcp, got '{}'", settings.transport));
    }
    av_dict_set(&options, "rtsp_transport", settings.transport.c_str(), 0);
    av_dict_set_int(&options, "timeout", timeout, 0);
  } else if (settings.url.starts_with("udp://")) {
    format = av_find_input_format("mpegts");
    // A big socket buffer and a reading thread: no datagram is lost while a picture is decoded.
    address += fmt::format("{}timeout={}&fifo_size=1000000&overrun_nonfatal=1&buffer_size=8388608",
                           address.find('?') == std::string::npos ? "?" : "&", timeout);
    av_dict_set(&options, "probesize", "5000000", 0);
  } else {
    av_dict_free(&options);
    throw std::runtime_error(
        fmt::format("expected rtsp://HOST:PORT/NAME or udp://HOST:PORT, got '{}'", url));
  }
  AVFormatContext* raw = nullptr;
  const int opened = avformat_open_input(&raw, address.c_str(), format, &options);
  av_dict_free(&options);
  if (opened < 0) {
    throw std::runtime_error(fmt::format("cannot open {}: {}", url, ffmpeg::errorText(opened)));
  }
  input.reset(raw);
  // The codec is known from the SDP or the MPEG-TS tables; only where it is not, some of the
  // stream is read ahead to find it (those pictures then come late).
  stream = av_find_best_stream(input.get(), AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
  if (stream < 0 || input->streams[stream]->codecpar->codec_id == AV_CODEC_ID_NONE) {
    if (const int found = avformat_find_stream_info(input.get(), nullptr); found < 0) {
      throw std::runtime_error(fmt::format("{}: {}", url, ffmpeg::errorText(found)));
    }
    stream = av_find_best_stream(input.get(), AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
  }
  if (stream < 0) throw std::runtime_error(fmt::format("{}: no video stream", url));
  const AVCodecParameters* parameters = input->streams[stream]->codecpar;
  const AVCodec* decoder = avcodec_find_decoder(parameters->codec_id);
  if (decoder == nullptr) throw std::runtime_error(fmt::format("{}: no decoder", url));
  codec.reset(avcodec_alloc_context3(decoder));
  if (!codec || !packet || !frame) throw std::runtime_error("out of memory");
  avcodec_parameters_to_context(codec.get(), parameters);
  // Frame threads would hold pictures back; slices decode side by side without delay.
  codec->thread_type = FF_THREAD_SLICE;
  codec->flags |= AV_CODEC_FLAG_LOW_DELAY;
  if (const int error = avcodec_open2(codec.get(), decoder, nullptr); error < 0) {
    throw std::runtime_error(
        fmt::format("{}: cannot open the decoder: {}", url, ffmpeg::errorText(error)));
  }
}

ViewedPicture StreamViewer::Impl::convert() {
  ViewedPicture picture;
  picture.decoded = std::chrono::system_clock::now();
  for (int i = 0; i < frame->nb_side_data; ++i) {
    const AVFrameSideData& data = *frame->side_data[i];
    if (data.type != AV_FRAME_DATA_SEI_UNREGISTERED) continue;
    if (auto captured = render::captureTimeFromSei({data.data, data.size})) {
      picture.captured = captured;
    }
  }
  sws = sws_getCachedContext(sws, frame->width, frame->height,
                             static_cast<AVPixelFormat>(frame->format), frame->width, frame->height,
                             AV_PIX_FMT_BGR24, SWS_BICUBIC, nullptr, nullptr, nullptr);
  if (sws == nullptr) throw std::runtime_error(fmt::format("{}: cannot convert a picture", url));
  picture.bgr.create(frame->height, frame->width, CV_8UC3);
  std::uint8_t* planes[] = {picture.bgr.data};
  const int strides[] = {static_cast<int>(picture.bgr.step[0])};
  sws_scale(sws, frame->data, frame->linesize, 0, frame->height, planes, strides);
  av_frame_unref(frame.get());
  return picture;
}

StreamViewer::StreamViewer(const StreamViewerSettings& settings) : impl_(std::make_unique<Impl>()) {
  impl_->url = settings.url;
  impl_->open(settings);
}

StreamViewer::~StreamViewer() = default;

std::optional<ViewedPicture> StreamViewer::next() {
  Impl& s = *impl_;
  for (;;) {
    const int received = avcodec_receive_frame(s.codec.get(), s.frame.get());
    if (received == 0) return s.convert();
    if (received == AVERROR_EOF) return std::nullopt;
    if (received != AVERROR(EAGAIN)) {
      throw std::runtime_error(
          fmt::format("{}: decoding failed: {}", s.url, ffmpeg::errorText(received)));
    }
    if (s.flushed) return std::nullopt;
    if (av_read_frame(s.input.get(), s.packet.get()) < 0) {
      // The end (or silence): what the decoder still holds comes out first.
      avcodec_send_packet(s.codec.get(), nullptr);
      s.flushed = true;
      continue;
    }
    // A packet the decoder refuses (damaged by a lost datagram) is skipped, as a player does.
    if (s.packet->stream_index == s.stream) avcodec_send_packet(s.codec.get(), s.packet.get());
    av_packet_unref(s.packet.get());
  }
}

}  // namespace surroundd::bench
