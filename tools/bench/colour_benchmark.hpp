#pragma once
// surround-bench colour: Poisson local colour correction on the generator's recordings. Per input
// and correction scale: each solver on the real source region (set-up, cold and warm solve
// milliseconds, iterations, agreement with CHOLMOD); the per-frame cost of the whole correction
// (seam data + solve, upsample-and-apply); and the colour step across the seams before and after,
// against global gain compensation.

#include <filesystem>
#include <vector>

namespace surroundd::bench {

struct ColourBenchmarkOptions {
  std::vector<std::filesystem::path> recordings;
  int threads = 2;
  int repeats = 30;
};

int runColourBenchmark(const ColourBenchmarkOptions& options);

}  // namespace surroundd::bench
