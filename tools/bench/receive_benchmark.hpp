#pragma once
// surround-bench receive: a surroundd stream (RTSP or MPEG-TS over UDP) watched as a viewer would
// for a while: pictures per second, and capture to decoded picture from the capture times the
// stream carries, beside the ISO 16505 / IEC 63033-3 limits (>= 30 FPS, < 200 ms). On loopback this
// is the daemon's capture-to-output latency plus the encoder, the server and the network hop.

#include <chrono>
#include <filesystem>

#include "tools/bench/stream_viewer.hpp"

namespace surroundd::bench {

struct ReceiveBenchmarkOptions {
  StreamViewerSettings viewer;
  std::chrono::seconds duration{10};  // watched for at most this long (the stream may end first)
  std::filesystem::path lastPicture;  // if set, the last picture is written there (PNG, JPEG)
};

// Prints the figures; 0, or 1 when no picture came.
int runReceiveBenchmark(const ReceiveBenchmarkOptions& options);

}  // namespace surroundd::bench
