#pragma once
// Timing for benchmarks on a shared, noisy machine: candidates are run in turns (A, B, A, B, ...)
// so that a slow spell hits both, and each is summarized by its median.

#include <algorithm>
#include <chrono>
#include <functional>
#include <vector>

namespace surroundd::bench {

inline double millisecondsOf(const std::function<void()>& run) {
  const auto start = std::chrono::steady_clock::now();
  run();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

inline double median(std::vector<double> samples) {
  if (samples.empty()) return 0;
  const auto middle = samples.begin() + static_cast<std::ptrdiff_t>(samples.size() / 2);
  std::nth_element(samples.begin(), middle, samples.end());
  return *middle;
}

// Median milliseconds of each candidate over `repeats` turns, after one untimed warm-up turn.
inline std::vector<double> interleavedMedians(const std::vector<std::function<void()>>& candidates,
                                              int repeats) {
  for (const auto& candidate : candidates) candidate();
  std::vector<std::vector<double>> samples(candidates.size());
  for (int r = 0; r < repeats; ++r) {
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      samples[c].push_back(millisecondsOf(candidates[c]));
    }
  }
  std::vector<double> medians;
  for (auto& s : samples) medians.push_back(median(std::move(s)));
  return medians;
}

}  // namespace surroundd::bench
