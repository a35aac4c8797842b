#include "daemon/duration_histogram.hpp"

#include <algorithm>
#include <cmath>

namespace surroundd::daemon {
namespace {

constexpr double kFirstEdgeNs = 1e3;  // 1 µs

}  // namespace

std::chrono::nanoseconds DurationHistogram::upperEdge(std::size_t index) {
  return std::chrono::nanoseconds(static_cast<std::int64_t>(std::llround(
      kFirstEdgeNs * std::pow(10.0, static_cast<double>(index + 1) / kBucketsPerDecade))));
}

void DurationHistogram::record(std::chrono::nanoseconds duration) {
  const double ns = std::max(static_cast<double>(duration.count()), kFirstEdgeNs);
  // Bucket i holds (edge(i-1), edge(i)]: ceil, less one, of the position on the log scale.
  const double position = std::log10(ns / kFirstEdgeNs) * kBucketsPerDecade;
  const auto index = static_cast<std::size_t>(std::max(std::ceil(position - 1e-9) - 1.0, 0.0));
  ++buckets_[std::min(index, kBuckets - 1)];
  ++count_;
  sum_ += duration;
}

std::chrono::nanoseconds DurationHistogram::quantile(double fraction) const {
  if (count_ == 0) return std::chrono::nanoseconds(0);
  const auto rank = static_cast<std::uint64_t>(
      std::ceil(std::clamp(fraction, 0.0, 1.0) * static_cast<double>(count_)));
  std::uint64_t seen = 0;
  for (std::size_t i = 0; i < kBuckets; ++i) {
    seen += buckets_[i];
    if (seen >= std::max<std::uint64_t>(rank, 1)) return upperEdge(i);
  }
  return upperEdge(kBuckets - 1);
}

}  // namespace surroundd::daemon
