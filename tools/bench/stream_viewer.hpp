#pragma once
// A surroundd stream received and decoded the way a viewer's player does it (FFmpeg's libavformat
// and H.264 decoder, tuned for latency: no demuxer buffering, slice threads only): RTSP (rtsp://,
// RTP over UDP or interleaved in the RTSP connection) or MPEG-TS over UDP (udp://HOST:PORT, bound
// by the constructor). Each picture comes as BGR with the capture time the stream carries for it
// (render/outputs/capture_time_sei.hpp) and the wall clock when it was decoded: capture to
// picture, as the viewer sees it.
//
// Error policy: the constructor throws std::runtime_error naming the URL when it cannot open it
// or it has no video; next() returns none at the end of the stream (an RTCP BYE, the connection
// closed, or nothing for `timeout`) and throws std::runtime_error only for a decoder that fails.

#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

namespace surroundd::bench {

struct StreamViewerSettings {
  std::string url;                          // rtsp://HOST:PORT/NAME or udp://HOST:PORT
  std::string transport = "udp";            // RTSP: udp | tcp
  std::chrono::milliseconds timeout{5000};  // nothing for this long ends the stream
};

struct ViewedPicture {
  cv::Mat bgr;
  std::optional<std::chrono::system_clock::time_point> captured;  // if the stream says
  std::chrono::system_clock::time_point decoded;
};

class StreamViewer {
 public:
  explicit StreamViewer(const StreamViewerSettings& settings);  // connects (RTSP) or binds (UDP)
  ~StreamViewer();
  StreamViewer(const StreamViewer&) = delete;
  StreamViewer& operator=(const StreamViewer&) = delete;

  // The next picture; none when the stream has ended.
  std::optional<ViewedPicture> next();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace surroundd::bench
