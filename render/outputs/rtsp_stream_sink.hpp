#pragma once
// H.264 served over RTSP (GStreamer's gst-rtsp-server) at rtsp://ADDRESS:PORT/NAME, to any number
// of viewers at once, each over RTP/UDP or interleaved in its RTSP connection as it asks. One
// encoder (VideoEncoder, tuned for latency, each picture stamped with its capture time) feeds them
// all through one shared GStreamer pipeline (appsrc ! rtph264pay). Nothing is encoded while nobody
// watches; a viewer that starts playing gets a keyframe with the next picture. At the end the
// viewers are told (RTCP BYE) and given a moment to leave before the server closes.
//
// Threads: the server runs a GLib main loop on a thread of its own; its callbacks share with the
// caller only the way into the pipeline (under a mutex) and counters (atomics). consume() and
// finish() are called from one thread at a time (an output queue's); wantsFrame() from any.
//
// Error policy: the constructor throws std::runtime_error naming the address when it cannot listen
// or a GStreamer element it needs is missing (with the Debian package that has it), and
// EncoderError when the encoder cannot open; consume() throws EncoderError.

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "render/outputs/credentials.hpp"
#include "render/outputs/frame_sink.hpp"
#include "render/outputs/video_encoder.hpp"

namespace surroundd::render {

struct RtspStreamSettings {
  std::string address = "0.0.0.0";  // IPv4 address to listen on; 0.0.0.0: every interface
  int port = 8554;                  // TCP port; 0: any free one (see port())
  std::string name = "surround";    // the path: rtsp://ADDRESS:PORT/<name>
  // The pictures' size and rate, encoder, crf, preset, pixel format (path and url unused).
  VideoEncoderSettings video;
  // Who may watch (RTSP basic authentication); none: anyone who reaches the address.
  std::optional<Credentials> credentials;
};

class RtspStreamSink final : public FrameSink {
 public:
  explicit RtspStreamSink(RtspStreamSettings settings);  // listens at once
  ~RtspStreamSink() override;                            // closes the server if finish() did not

  void consume(const cv::Mat& picture, const PictureTime& time) override;
  bool takesI420() const override;
  // Whether a viewer is watching (or about to).
  bool wantsFrame(std::chrono::nanoseconds streamTime) const override;
  void finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) override;
  std::string describe() const override;

  int port() const;         // the one it listens on
  std::string url() const;  // rtsp://ADDRESS:PORT/NAME
  int viewers() const;      // viewers connected now

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace surroundd::render
