#pragma once
// Where rendered frames go. Each picture output in the config is one FrameSink; the pipeline hands
// every sink each frame it wants, in stream order, then finish() once. The sinks are one header
// each beside this one (video_sink.hpp, snapshot_sink.hpp, http_stream_sink.hpp, ...).
//
// Threads: a sink that may block (an encoder, a display's vblank, JPEG encoding, a network write)
// runs behind a QueuedSink: its consume() runs on the queue's thread while the pipeline thread may
// ask its wantsFrame(), takesI420() and page(), so a sink keeps those three safe for that.
//
// Error policy: consume() and finish() throw (EncoderError, std::runtime_error) naming the file;
// the pipeline logs the failure and drops that sink, the others go on.

#include <chrono>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

#include <opencv2/core.hpp>

#include "render/outputs/view_page.hpp"

namespace surroundd::render {

class SurroundView;

// When a picture's frame set was taken. A stream time alone converts: its capture time is then
// unknown (a test's picture, a replay's last frame).
struct PictureTime {
  template <class Rep, class Period>
  PictureTime(std::chrono::duration<Rep, Period> streamTime,  // NOLINT(google-explicit-constructor)
              std::optional<std::chrono::system_clock::time_point> capturedAt = std::nullopt)
      : stream(streamTime), captured(capturedAt) {}

  std::chrono::nanoseconds stream;  // counts from the first frame of the run
  // The wall clock when the cameras took it; a live stream carries it to its viewers (see
  // VideoEncoderSettings::stampCaptureTime).
  std::optional<std::chrono::system_clock::time_point> captured;
};

// Pictures are 8-bit BGR (CV_8UC3); a sink that takesI420() may be handed I420 ones instead, made
// for its encoder as the picture was finished (processing/stitch/i420_picture.hpp): CV_8UC1,
// continuous, of width x height * 3 / 2, the luma plane then the Cb and the Cr one.
inline bool isI420(const cv::Mat& picture, cv::Size size) {
  return picture.type() == CV_8UC1 && picture.isContinuous() && picture.cols == size.width &&
         picture.rows == size.height * 3 / 2;
}

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  FrameSink() = default;
  FrameSink(const FrameSink&) = delete;
  FrameSink& operator=(const FrameSink&) = delete;

  // `picture` is 8-bit BGR, or I420 where takesI420().
  virtual void consume(const cv::Mat& picture, const PictureTime& time) = 0;
  // Whether its pictures may come in I420 (an H.264 encoder's own format), sparing it the
  // conversion. A picture made another way (drawn by OpenGL) still comes in BGR.
  virtual bool takesI420() const { return false; }
  // Whether it shows a surround view as OpenGL drew it, on the GPU, with no picture read back (a
  // window through EGL): the pipeline then hands it present() instead of consume(), on the
  // renderer's thread.
  virtual bool presentsViews() const { return false; }
  // Shows `view`'s picture, just drawn (SurroundView::ReadBack::kNo). Throws as consume().
  virtual void present(const SurroundView& /*view*/, const PictureTime& /*time*/) {
    throw std::logic_error("this output shows no views on the GPU");
  }
  // Whether the frame at `streamTime` is needed: the pipeline skips making pictures (renders) that
  // no sink wants.
  virtual bool wantsFrame(std::chrono::nanoseconds /*streamTime*/) const { return true; }
  // The run is over; `lastFrame` is the picture of the run's last frame, at `lastTime` (empty if
  // there was none).
  virtual void finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) = 0;
  // What was written, for the log ("video /out/demo/mosaic.mp4 (300 frames)").
  virtual std::string describe() const = 0;
  // Pictures it was given but dropped because it fell behind (see QueuedSink).
  virtual std::uint64_t dropped() const { return 0; }
  // A page a viewer acts on (views asked for, status shown), or null: the pipeline asks every
  // output for one instead of knowing which kind has one. Borrowed; lives as long as the sink.
  virtual ViewPage* page() { return nullptr; }
};

}  // namespace surroundd::render
