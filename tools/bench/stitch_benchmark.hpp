#pragma once
// surround-bench stitch: LUT build time, stitch milliseconds against cv::remap on the same maps,
// the top view through its view LUT against the panorama stitched and rendered, and the
// panorama's accuracy against the generator's ground truth (bowl and sphere projections).

#include <filesystem>
#include <vector>

namespace surroundd::bench {

struct StitchBenchmarkOptions {
  std::vector<std::filesystem::path> recordings;  // surround-synth folders with ground truth
  int threads = 2;
  int repeats = 30;
  bool json = false;
};

int runStitchBenchmark(const StitchBenchmarkOptions& options);

}  // namespace surroundd::bench
