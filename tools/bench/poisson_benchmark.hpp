#pragma once
// The Poisson solvers of colour correction, one system at a time: set-up (analysis and
// factorization, multigrid hierarchy, DCT tables), solve milliseconds from a cold start and
// warm-started on a slowly changing sequence of right-hand sides (as frames give them),
// iterations, residual, and agreement with CHOLMOD.

#include <cstddef>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/colour/poisson_correction.hpp"
#include "processing/colour/poisson_solver.hpp"

namespace surroundd::bench {

struct PoissonBenchmarkOptions {
  int repeats = 30;  // frames solved per solver; medians reported
  // The iterative solver's relative residual: the colour correction's default.
  double tolerance = processing::ColourCorrectionSettings{}.tolerance;
};

struct PoissonSolverTiming {
  processing::PoissonSolverKind kind = processing::PoissonSolverKind::kCholmod;
  std::size_t unknowns = 0;  // of the system measured
  double setupMs = 0;
  double coldSolveMs = 0;          // from x = 0
  double warmSolveMs = 0;          // median over frames, started from the previous frame's solution
  int coldIterations = 0;          // 0 for direct solvers
  int warmIterations = 0;          // median
  double relativeResidual = 0;     // last frame
  double differenceToCholmod = 0;  // largest |x - x_cholmod| on the last frame, 8-bit levels
};

// Frame f's right-hand sides: smooth seam values of 0..60 levels at every Dirichlet neighbour,
// scaled by 1.01^f and with noise of 0.2 levels: what a slow exposure drift gives.
processing::ChannelValues seamRightHandSides(const processing::PoissonSystem& system, int frame);

// CHOLMOD and the iterative solver, interleaved frame by frame on one thread.
std::vector<PoissonSolverTiming> benchmarkPoissonSolvers(const processing::PoissonSystem& system,
                                                         const PoissonBenchmarkOptions& options);

// A text table; `size` is the region's frame.
std::string formatPoissonTimings(cv::Size size, const std::vector<PoissonSolverTiming>& timings);

}  // namespace surroundd::bench
