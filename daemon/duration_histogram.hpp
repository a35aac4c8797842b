#pragma once
// A histogram of durations with fixed log-spaced buckets: record() is a few instructions and never
// allocates, so the per-frame path can feed one per stage; quantiles are read from the buckets.
//
// Buckets are 40 per decade from 1 µs to 100 s, so a quantile is exact to within one bucket (6 %);
// shorter and longer durations land in the first and last. Counts are since construction.
// Threads: one writer, and readers on the same thread (the pipeline thread answers metrics).

#include <array>
#include <chrono>
#include <cstdint>

namespace surroundd::daemon {

class DurationHistogram {
 public:
  static constexpr int kBucketsPerDecade = 40;
  static constexpr int kDecades = 8;  // 1 µs .. 100 s
  static constexpr std::size_t kBuckets = kBucketsPerDecade * kDecades;

  void record(std::chrono::nanoseconds duration);

  std::uint64_t count() const { return count_; }
  std::chrono::nanoseconds sum() const { return sum_; }
  // The duration below which `fraction` (0..1) of the recorded ones lie: the upper edge of the
  // bucket it falls in. Zero when nothing was recorded.
  std::chrono::nanoseconds quantile(double fraction) const;
  // The upper edge of bucket `index`.
  static std::chrono::nanoseconds upperEdge(std::size_t index);

 private:
  std::array<std::uint64_t, kBuckets> buckets_{};
  std::uint64_t count_ = 0;
  std::chrono::nanoseconds sum_{0};
};

}  // namespace surroundd::daemon
