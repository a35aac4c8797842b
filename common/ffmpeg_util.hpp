#pragma once
// RAII owners for FFmpeg objects and FFmpeg error text, shared by capture/ (decoding) and render/
// (encoding). Header-only and in its own folder so that neither library depends on the other.

#include <memory>
#include <string>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/error.h>
#include <libavutil/frame.h>
#include <libswscale/swscale.h>
}

namespace surroundd::ffmpeg {

// A demuxer opened with avformat_open_input().
struct InputFormatDeleter {
  void operator()(AVFormatContext* context) const noexcept { avformat_close_input(&context); }
};

// A muxer from avformat_alloc_output_context2(); also closes the file it writes to, if opened.
struct OutputFormatDeleter {
  void operator()(AVFormatContext* context) const noexcept {
    if (context->pb != nullptr && (context->oformat->flags & AVFMT_NOFILE) == 0) {
      avio_closep(&context->pb);
    }
    avformat_free_context(context);
  }
};

struct CodecContextDeleter {
  void operator()(AVCodecContext* context) const noexcept { avcodec_free_context(&context); }
};

struct FrameDeleter {
  void operator()(AVFrame* frame) const noexcept { av_frame_free(&frame); }
};

struct PacketDeleter {
  void operator()(AVPacket* packet) const noexcept { av_packet_free(&packet); }
};

struct BufferDeleter {
  void operator()(AVBufferRef* buffer) const noexcept { av_buffer_unref(&buffer); }
};

struct SwsContextDeleter {
  void operator()(SwsContext* context) const noexcept { sws_freeContext(context); }
};

using InputFormatPtr = std::unique_ptr<AVFormatContext, InputFormatDeleter>;
using OutputFormatPtr = std::unique_ptr<AVFormatContext, OutputFormatDeleter>;
using CodecContextPtr = std::unique_ptr<AVCodecContext, CodecContextDeleter>;
using FramePtr = std::unique_ptr<AVFrame, FrameDeleter>;
using PacketPtr = std::unique_ptr<AVPacket, PacketDeleter>;
using SwsContextPtr = std::unique_ptr<SwsContext, SwsContextDeleter>;
using BufferPtr = std::unique_ptr<AVBufferRef, BufferDeleter>;

// While one lives, FFmpeg's messages from this thread are about failures its caller expects and
// reports in its own words (a hardware encoder tried where there is none): the daemon's log takes
// them at debug level instead of as errors (daemon/config/logging.hpp routes FFmpeg's log).
class ExpectedFailures {
 public:
  ExpectedFailures() { ++depth(); }
  ~ExpectedFailures() { --depth(); }
  ExpectedFailures(const ExpectedFailures&) = delete;
  ExpectedFailures& operator=(const ExpectedFailures&) = delete;

  static bool active() { return depth() > 0; }

 private:
  static int& depth() {
    thread_local int depth = 0;
    return depth;
  }
};

// av_err2str() is a C macro built on a compound literal, which C++ does not have.
inline std::string errorText(int error) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(error, text, sizeof(text));
  return text;
}

}  // namespace surroundd::ffmpeg
