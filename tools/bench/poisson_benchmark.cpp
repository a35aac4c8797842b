#include "tools/bench/poisson_benchmark.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>

#include <fmt/format.h>

#include "processing/colour/poisson_matrix.hpp"
#include "tools/bench/timing.hpp"

namespace surroundd::bench {

using processing::ChannelValues;
using processing::PoissonSolverKind;
using processing::PoissonSystem;

ChannelValues seamRightHandSides(const PoissonSystem& system, int frame) {
  const processing::PoissonMatrix matrix(system);
  std::mt19937 random(static_cast<unsigned>(frame) + 1);
  std::normal_distribution<double> noise(0.0, 0.2);
  const double gain = std::pow(1.01, frame);
  ChannelValues rhs(3 * system.unknowns(), 0.0f);
  for (std::size_t i = 0; i < system.unknowns(); ++i) {
    const int seams = matrix.degree(i) - static_cast<int>(matrix.neighbours(i).size());
    const cv::Point p = system.pixels[i];
    for (int s = 0; s < seams; ++s) {
      for (std::size_t c = 0; c < 3; ++c) {
        // Smooth along the seam, different per channel and side, within 0..60 levels.
        const double value =
            30 + 25 * std::sin(0.05 * p.y + 1.3 * static_cast<double>(c) + 2.0 * s + 0.01 * p.x);
        rhs[3 * i + c] += static_cast<float>(gain * value + noise(random));
      }
    }
  }
  return rhs;
}

std::vector<PoissonSolverTiming> benchmarkPoissonSolvers(const PoissonSystem& system,
                                                         const PoissonBenchmarkOptions& options) {
  const std::vector<PoissonSolverKind> kinds = {PoissonSolverKind::kCholmod,
                                                PoissonSolverKind::kIterative};
  std::vector<ChannelValues> frames;
  for (int f = 0; f <= options.repeats; ++f) frames.push_back(seamRightHandSides(system, f));

  std::vector<PoissonSolverTiming> timings(kinds.size());
  std::vector<std::unique_ptr<processing::PoissonSolver>> solvers(kinds.size());
  std::vector<ChannelValues> solutions(kinds.size(), ChannelValues(3 * system.unknowns(), 0.0f));
  for (std::size_t s = 0; s < kinds.size(); ++s) {
    timings[s].kind = kinds[s];
    timings[s].unknowns = system.unknowns();
    timings[s].setupMs = millisecondsOf(
        [&] { solvers[s] = processing::makePoissonSolver(kinds[s], system, options.tolerance); });
  }
  // Cold: from zero, the median of a few runs.
  for (std::size_t s = 0; s < kinds.size(); ++s) {
    std::vector<double> samples;
    for (int run = 0; run < 5; ++run) {
      std::ranges::fill(solutions[s], 0.0f);
      samples.push_back(millisecondsOf([&] {
        timings[s].coldIterations = solvers[s]->solve(frames[0], solutions[s]).iterations;
      }));
    }
    timings[s].coldSolveMs = median(std::move(samples));
  }
  // Warm: frame after frame, each solver starting from its previous solution; interleaved so
  // that a slow spell of the machine hits all of them.
  std::vector<std::vector<double>> samples(kinds.size());
  std::vector<std::vector<double>> iterations(kinds.size());
  for (int f = 1; f <= options.repeats; ++f) {
    for (std::size_t s = 0; s < kinds.size(); ++s) {
      processing::SolveStats stats;
      samples[s].push_back(millisecondsOf(
          [&] { stats = solvers[s]->solve(frames[static_cast<std::size_t>(f)], solutions[s]); }));
      iterations[s].push_back(stats.iterations);
      timings[s].relativeResidual = stats.relativeResidual;
    }
  }
  for (std::size_t s = 0; s < kinds.size(); ++s) {
    timings[s].warmSolveMs = median(std::move(samples[s]));
    timings[s].warmIterations = static_cast<int>(median(std::move(iterations[s])));
    double largest = 0;
    for (std::size_t i = 0; i < solutions[s].size(); ++i) {
      largest = std::max(largest, static_cast<double>(std::abs(solutions[s][i] - solutions[0][i])));
    }
    timings[s].differenceToCholmod = largest;
  }
  return timings;
}

std::string formatPoissonTimings(cv::Size size, const std::vector<PoissonSolverTiming>& timings) {
  const std::size_t unknowns = timings.empty() ? 0 : timings.front().unknowns;
  std::string text = fmt::format("Poisson system {}x{} ({} unknowns, 3 channels), 1 thread\n",
                                 size.width, size.height, unknowns);
  text += fmt::format("  {:<10} {:>10} {:>10} {:>6} {:>10} {:>6} {:>10} {:>10}\n", "solver",
                      "set-up ms", "cold ms", "iter", "warm ms", "iter", "residual", "vs cholmod");
  for (const auto& t : timings) {
    text += fmt::format("  {:<10} {:>10.2f} {:>10.3f} {:>6} {:>10.3f} {:>6} {:>10.1e} {:>10.4f}\n",
                        processing::poissonSolverName(t.kind), t.setupMs, t.coldSolveMs,
                        t.coldIterations, t.warmSolveMs, t.warmIterations, t.relativeResidual,
                        t.differenceToCholmod);
  }
  return text;
}

}  // namespace surroundd::bench
