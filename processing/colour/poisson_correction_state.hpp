#pragma once
// The state behind PoissonColourCorrection (poisson_correction.hpp), shared by its two halves:
// poisson_correction.cpp (set-up, solve, upsample and apply) and poisson_seam_data.cpp (the seam
// data of each frame and the rule that no seam gets worse). Not part of the public interface.

#include <cstdint>
#include <memory>
#include <vector>

#include "processing/colour/poisson_correction.hpp"

namespace surroundd::processing {

// Half-width of the running median along a seam, in blocks: wide enough to outvote an object or a
// parallax streak a few blocks long, narrow enough to follow vignetting along the seam.
inline constexpr int kSeamHalfWindow = 3;

struct PoissonColourCorrection::RegionState {
  std::unique_ptr<PoissonSolver> solver;
  // Per Dirichlet block: this frame's levels, and 3 values each of log(target / source), or
  // target - source in levels (additive): as measured, filtered along the seam and bounded, and
  // smoothed over time. `dirichlet` is what is solved: the smoothed data, 0 on dropped seams.
  std::vector<SeamBlockLevels> levels;
  std::vector<std::uint8_t> measuredValid, filteredValid;
  std::vector<float> measured, filtered, seamValue;
  std::vector<float> dirichlet;
  std::vector<float> rhs;
  std::vector<float> solution;  // 3 per unknown; the warm start of the next frame
  // Where a seam's data is dropped the region is solved twice a frame, with its data and without
  // the dropped part. Each solve warm-starts from its own kind of the frame before: `solution`
  // and `otherSolution` swap, so that neither starts from the other's field (an iterative solver
  // would then need most of a cold solve's iterations, twice a frame). `solvedTwice`: last frame.
  std::vector<float> otherSolution;
  bool solvedTwice = false;
  int iterations = 0;
};

struct PoissonColourCorrection::Configuration {
  CorrectionDomain domain;
  std::vector<RegionState> regions;
  std::vector<float> slots;  // 3 values per field slot
  bool firstFrame = true;
  // Per seam: whether its clamp, its lack of data and its dropping have been said.
  std::vector<std::uint8_t> saidClamped, saidSparse, saidDropped;
};

}  // namespace surroundd::processing
