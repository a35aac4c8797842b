// The iterative solver: conjugate gradients on the region's grid, preconditioned by one geometric
// multigrid V-cycle per iteration (PoissonMultigrid), started from the previous frame's
// solution. Seam data drift slowly from frame to frame, so the start is already close and one or
// two V-cycles reach the tolerance.
//
// Each channel is its own CG run; all three stop at |r_c|^2 <= tolerance^2 |b|^2 / 3, so that
// |r| <= tolerance |b| over the three. Mixed precision: the solution, the residual and A p are
// kept in double, so the residual recurrence stays true to b - A x at any tolerance (in float
// it drifts from it near 1e-6, and long thin regions need far less to be accurate); the search
// directions and the V-cycle only steer, and run in float at twice the speed.

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "processing/colour/float_lanes.hpp"
#include "processing/colour/poisson_matrix.hpp"
#include "processing/colour/poisson_multigrid.hpp"
#include "processing/colour/poisson_solver.hpp"

namespace surroundd::processing {
namespace {

// A V-cycle cuts the residual 20 to 50 times on compact regions; regions riddled with holes take
// a few times more. This many means the tolerance cannot be reached.
constexpr int kMaxIterations = 50;

double sumOf(FloatLanes lanes) {
  return static_cast<double>(lanes[0]) + lanes[1] + lanes[2] + lanes[3];
}
double sumOf(DoubleLanes lanes) { return lanes[0] + lanes[1]; }

double squaredNorm(std::span<const float> values) {
  // Two accumulators: the adds of one do not wait for the other's.
  DoubleLanes even = {0, 0};
  DoubleLanes odd = {0, 0};
  std::size_t i = 0;
  for (; i + 4 <= values.size(); i += 4) {
    const DoubleLanes a = loadWidened(values.data() + i);
    const DoubleLanes b = loadWidened(values.data() + i + 2);
    even += a * a;
    odd += b * b;
  }
  double sum = sumOf(even + odd);
  for (; i < values.size(); ++i) sum += static_cast<double>(values[i]) * values[i];
  return sum;
}

class IterativeSolver final : public PoissonSolver {
 public:
  IterativeSolver(const PoissonSystem& system, double tolerance)
      : tolerance_(tolerance),
        multigrid_(system),
        width_(system.size.width),
        height_(system.size.height),
        stride_(multigrid_.stride()) {
    if (!(tolerance > 0 && tolerance < 1)) {
      throw std::invalid_argument(
          fmt::format("iterative Poisson solver: tolerance {} is not in (0, 1)", tolerance));
    }
    for (auto* plane : {&node_, &degree_, &b_, &residualFloat_}) {
      plane->assign(multigrid_.gridSize(), 0.0f);
    }
    for (auto* plane : {&nodeDouble_, &degreeDouble_, &x_, &r_, &p_, &q_}) {
      plane->assign(multigrid_.gridSize(), 0.0);
    }
    for (std::size_t i = 0; i < system.unknowns(); ++i) {
      const std::size_t cell = multigrid_.cellOf(system.pixels[i]);
      cells_.push_back(cell);
      node_[cell] = 1;
      degree_[cell] = static_cast<float>(system.degree[i]);
      nodeDouble_[cell] = 1;
      degreeDouble_[cell] = system.degree[i];
    }
  }

  PoissonSolverKind kind() const override { return PoissonSolverKind::kIterative; }

  SolveStats solve(std::span<const float> rhs, std::span<float> x) override {
    checkChannelSpans(cells_.size(), rhs.size(), x.size());
    const double rhsSquared = squaredNorm(rhs);
    if (rhsSquared == 0) {
      std::ranges::fill(x, 0.0f);
      return {};
    }
    const double stopSquared = tolerance_ * tolerance_ * rhsSquared / 3;
    SolveStats stats;
    double residualSquared = 0;
    for (std::size_t c = 0; c < 3; ++c) {
      for (std::size_t i = 0; i < cells_.size(); ++i) {
        x_[cells_[i]] = x[3 * i + c];
        b_[cells_[i]] = rhs[3 * i + c];
      }
      const auto [iterations, channelSquared] = solveChannel(stopSquared);
      for (std::size_t i = 0; i < cells_.size(); ++i) {
        x[3 * i + c] = static_cast<float>(x_[cells_[i]]);
      }
      stats.iterations = std::max(stats.iterations, iterations);
      residualSquared += channelSquared;
    }
    stats.relativeResidual = std::sqrt(residualSquared / rhsSquared);
    return stats;
  }

 private:
  // Preconditioned CG on x_ for b_; returns the iterations and |r|^2 at the end.
  std::pair<int, double> solveChannel(double stopSquared) {
    double residualSquared = initialResidual();
    double rz = 0;
    int iteration = 0;
    for (; iteration < kMaxIterations && residualSquared > stopSquared; ++iteration) {
      const float* z = multigrid_.vcycle(residualFloat_.data());
      const double previousRz = rz;
      rz = dot(residualFloat_.data(), z);
      const double beta = iteration == 0 ? 0.0 : rz / previousRz;
      forEachCell<kDoubleLanes>([&](std::size_t c) {
        storeLanes(&p_[c], loadWidened(z + c) + beta * loadLanes(&p_[c]));
      });
      residualSquared = step(rz / applyMatrix());
    }
    return {iteration, residualSquared};
  }

  // Calls body(c) for the first cell c of every `lanes` along the region's rows (off the region
  // the planes hold zero, so the lanes that run past a row's end change nothing).
  template <int kLanes, typename Body>
  void forEachCell(Body&& body) const {
    for (int y = 0; y < height_; ++y) {
      const std::size_t begin = static_cast<std::size_t>(y + 1) * stride_ + 1;
      for (std::size_t c = begin; c < begin + width_; c += kLanes) body(c);
    }
  }

  double dot(const float* a, const float* b) const {
    FloatLanes sum = {0, 0, 0, 0};
    forEachCell<kFloatLanes>([&](std::size_t c) { sum += loadLanes(a + c) * loadLanes(b + c); });
    return sumOf(sum);
  }

  // r = b - A x in double, and in float for the V-cycle; returns |r|^2.
  double initialResidual() {
    const auto stride = static_cast<std::size_t>(stride_);
    DoubleLanes squared = {0, 0};
    forEachCell<kDoubleLanes>([&](std::size_t c) {
      const DoubleLanes ax = loadWidened(&degree_[c]) * loadLanes(&x_[c]) - loadLanes(&x_[c - 1]) -
                             loadLanes(&x_[c + 1]) - loadLanes(&x_[c - stride]) -
                             loadLanes(&x_[c + stride]);
      const DoubleLanes r = loadWidened(&node_[c]) * (loadWidened(&b_[c]) - ax);
      storeLanes(&r_[c], r);
      storeNarrowed(&residualFloat_[c], r);
      squared += r * r;
    });
    return sumOf(squared);
  }

  // q = A p in double (for a smooth p, A p is a small difference of large terms: in float it
  // would carry errors that the recurrence for r adds up); returns p . q.
  double applyMatrix() {
    const auto stride = static_cast<std::size_t>(stride_);
    DoubleLanes product = {0, 0};
    forEachCell<kDoubleLanes>([&](std::size_t c) {
      const DoubleLanes p = loadLanes(&p_[c]);
      const DoubleLanes q =
          loadLanes(&nodeDouble_[c]) *
          (loadLanes(&degreeDouble_[c]) * p - loadLanes(&p_[c - 1]) - loadLanes(&p_[c + 1]) -
           loadLanes(&p_[c - stride]) - loadLanes(&p_[c + stride]));
      storeLanes(&q_[c], q);
      product += p * q;
    });
    return sumOf(product);
  }

  // x += alpha p, r -= alpha q; returns |r|^2.
  double step(double alpha) {
    DoubleLanes squared = {0, 0};
    forEachCell<kDoubleLanes>([&](std::size_t c) {
      storeLanes(&x_[c], loadLanes(&x_[c]) + alpha * loadLanes(&p_[c]));
      const DoubleLanes r = loadLanes(&r_[c]) - alpha * loadLanes(&q_[c]);
      storeLanes(&r_[c], r);
      storeNarrowed(&residualFloat_[c], r);
      squared += r * r;
    });
    return sumOf(squared);
  }

  double tolerance_;
  PoissonMultigrid multigrid_;
  int width_;
  int height_;
  int stride_;
  std::vector<std::size_t> cells_;  // grid cell of each unknown
  // Planes on the multigrid's level-0 layout, zero off the region.
  std::vector<float> node_, degree_, b_;
  std::vector<double> x_, r_;         // the solution and its residual
  std::vector<float> residualFloat_;  // r for the V-cycle
  std::vector<double> nodeDouble_, degreeDouble_;
  std::vector<double> p_, q_;  // the search direction, A p
};

}  // namespace

std::unique_ptr<PoissonSolver> makeIterativeSolver(const PoissonSystem& system, double tolerance) {
  const PoissonMatrix matrix(system);  // checks the system
  if (const auto floating = matrix.floatingUnknown()) {
    throw std::runtime_error(fmt::format(
        "iterative Poisson solver: unknown {} is in a part of the region without a Dirichlet "
        "neighbour (the matrix is singular)",
        *floating));
  }
  return std::make_unique<IterativeSolver>(system, tolerance);
}

}  // namespace surroundd::processing
