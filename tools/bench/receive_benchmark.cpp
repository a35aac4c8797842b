#include "tools/bench/receive_benchmark.hpp"

#include <algorithm>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "daemon/compliance_limits.hpp"

namespace surroundd::bench {
namespace {

double milliseconds(std::chrono::nanoseconds duration) {
  return std::chrono::duration<double, std::milli>(duration).count();
}

// The duration below which `fraction` of the sorted `durations` lie (nearest rank).
std::chrono::nanoseconds quantile(const std::vector<std::chrono::nanoseconds>& durations,
                                  double fraction) {
  const auto rank = static_cast<std::size_t>(fraction * static_cast<double>(durations.size()));
  return durations[std::min(rank, durations.size() - 1)];
}

}  // namespace

int runReceiveBenchmark(const ReceiveBenchmarkOptions& options) {
  namespace limits = daemon::limits;
  StreamViewer viewer(options.viewer);
  const auto start = std::chrono::steady_clock::now();
  const auto end = start + options.duration;
  std::size_t pictures = 0;
  cv::Mat last;
  std::optional<std::chrono::steady_clock::time_point> first;
  std::chrono::steady_clock::time_point lastAt;
  std::vector<std::chrono::nanoseconds> latencies;
  while (std::chrono::steady_clock::now() < end) {
    auto picture = viewer.next();
    if (!picture) break;
    lastAt = std::chrono::steady_clock::now();
    if (!first) first = lastAt;
    ++pictures;
    if (picture->captured) latencies.push_back(picture->decoded - *picture->captured);
    last = std::move(picture->bgr);
  }
  const bool rtsp = options.viewer.url.starts_with("rtsp://");
  fmt::print("{}{}, watched {:.1f} s\n", options.viewer.url,
             rtsp ? fmt::format(" over {}", options.viewer.transport) : "",
             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  if (pictures == 0) {
    fmt::print("  no picture came\n");
    return 1;
  }
  // The rate between the first and the last picture: the wait for the first one is not in it.
  const double seconds = std::chrono::duration<double>(lastAt - *first).count();
  const double rate = pictures > 1 && seconds > 0 ? static_cast<double>(pictures - 1) / seconds : 0;
  fmt::print("  pictures           {} ({}x{}), {:.1f} per second ({}: >= {:.0f}: {})\n", pictures,
             last.cols, last.rows, rate, limits::kFrameRateAndLatencyStandard,
             limits::kMinFramesPerSecond, limits::frameRateMet(rate) ? "met" : "NOT met");
  if (latencies.empty()) {
    fmt::print("  capture to picture unknown: the stream carries no capture times\n");
  } else {
    std::sort(latencies.begin(), latencies.end());
    const auto p99 = quantile(latencies, 0.99);
    fmt::print(
        "  capture to picture p50 {:.1f} ms, p90 {:.1f} ms, p99 {:.1f} ms, max {:.1f} ms "
        "({} stamped; {}: p99 < {} ms: {})\n",
        milliseconds(quantile(latencies, 0.5)), milliseconds(quantile(latencies, 0.9)),
        milliseconds(p99), milliseconds(latencies.back()), latencies.size(),
        limits::kFrameRateAndLatencyStandard, limits::kMaxLatency.count(),
        limits::latencyMet(p99) ? "met" : "NOT met");
  }
  if (!options.lastPicture.empty()) {
    if (!cv::imwrite(options.lastPicture.string(), last)) {
      fmt::print(stderr, "surround-bench: cannot write '{}'\n", options.lastPicture.string());
      return 1;
    }
    fmt::print("  last picture       {}\n", options.lastPicture.string());
  }
  return 0;
}

}  // namespace surroundd::bench
