// The exact solver for the region that seams at fixed azimuths make: unknowns filling a W x H
// rectangle, a Dirichlet neighbour left of every pixel of the left column and right of every
// pixel of the right column, Neumann at top and bottom. The matrix is then T_x (x) I + I (x) L_y:
// T_x = tridiag(-1, 2, -1) of size W (Dirichlet at both ends), L_y the Neumann Laplacian of size
// H. The orthonormal DCT-II diagonalizes L_y (eigenvalues 2 - 2 cos(pi k / H)), so a DCT along y
// leaves H independent tridiagonal systems T_x + lambda_k along x, solved by the Thomas algorithm
// with pivots computed once; an inverse DCT brings the solution back.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>

#include "processing/column_dct.hpp"
#include "processing/poisson_matrix.hpp"
#include "processing/poisson_solver.hpp"

namespace surroundd::processing {
namespace {

class RectangleSolver final : public PoissonSolver {
 public:
  explicit RectangleSolver(const PoissonSystem& system)
      : width_(system.size.width),
        height_(system.size.height),
        rowFloats_(3 * static_cast<std::size_t>(width_)),
        stride_((rowFloats_ + 7) / 8 * 8),  // a multiple of 8 for ColumnDct
        dct_(height_, static_cast<int>(stride_)),
        grid_(static_cast<std::size_t>(height_) * stride_, 0.0f),
        inversePivot_(static_cast<std::size_t>(width_) * height_),
        widenedStride_(rowFloats_ + 7),
        widened_(3 * widenedStride_, 0.0) {
    // Thomas algorithm for tridiag(-1, 2 + lambda_k, -1): pivots d_0 = 2 + lambda,
    // d_x = 2 + lambda - 1 / d_(x-1), all > 1, so elimination is stable without pivoting.
    for (int k = 0; k < height_; ++k) {
      const double diagonal = 4 - 2 * std::cos(std::numbers::pi * k / height_);
      double pivot = diagonal;
      for (int x = 0; x < width_; ++x) {
        if (x > 0) pivot = diagonal - 1 / pivot;
        inversePivot_[static_cast<std::size_t>(x) * height_ + k] = static_cast<float>(1 / pivot);
      }
    }
  }

  PoissonSolverKind kind() const override { return PoissonSolverKind::kRectangle; }

  SolveStats solve(std::span<const float> rhs, std::span<float> x) override {
    checkChannelSpans(static_cast<std::size_t>(width_) * height_, rhs.size(), x.size());
    for (int y = 0; y < height_; ++y) std::copy_n(rhs.data() + y * rowFloats_, rowFloats_, row(y));
    dct_.forward(grid_.data());
    solveTridiagonal();
    dct_.inverse(grid_.data());
    for (int y = 0; y < height_; ++y) std::copy_n(row(y), rowFloats_, x.data() + y * rowFloats_);
    return {0, relativeResidual(rhs)};
  }

 private:
  // Pixel x, channel c of row y at row(y)[3 x + c]; the padding at the end of a row stays zero.
  float* row(int y) { return grid_.data() + static_cast<std::size_t>(y) * stride_; }
  float* pixel(int y, int x) { return row(y) + 3 * static_cast<std::size_t>(x); }

  // For every frequency row k and channel, along x: a block of rows at a time, so that the
  // block stays in L1 through both sweeps and the inner loop runs over independent systems
  // (within one row each step would wait for the previous one).
  void solveTridiagonal() {
    constexpr int kBlockRows = 8;
    const auto pivots = [this](int x) {
      return inversePivot_.data() + static_cast<std::size_t>(x) * height_;
    };
    for (int first = 0; first < height_; first += kBlockRows) {
      const int last = std::min(first + kBlockRows, height_);
      for (int x = 1; x < width_; ++x) {  // forward: y_x = b_x + y_(x-1) / d_(x-1)
        const float* previousPivot = pivots(x - 1);
        for (int k = first; k < last; ++k) {
          float* values = pixel(k, x);
          const float m = previousPivot[k];
          values[0] += m * values[-3];
          values[1] += m * values[-2];
          values[2] += m * values[-1];
        }
      }
      for (int k = first; k < last; ++k) {  // back: u_(W-1) = y_(W-1) / d_(W-1)
        float* values = pixel(k, width_ - 1);
        const float m = pivots(width_ - 1)[k];
        for (int c = 0; c < 3; ++c) values[c] *= m;
      }
      for (int x = width_ - 2; x >= 0; --x) {  // u_x = (y_x + u_(x+1)) / d_x
        const float* pivot = pivots(x);
        for (int k = first; k < last; ++k) {
          float* values = pixel(k, x);
          const float m = pivot[k];
          values[0] = (values[0] + values[3]) * m;
          values[1] = (values[1] + values[4]) * m;
          values[2] = (values[2] + values[5]) * m;
        }
      }
    }
  }

  // |b - A x| / |b| in double for the solution in the grid: what PoissonMatrix::relativeResidual
  // gives, without its index lists. Each row is widened to double once, into three rolling
  // buffers with zeros around them (the neighbours that are not unknowns); the seams on the left
  // and right count in the degree, Neumann above and below does not.
  double relativeResidual(std::span<const float> rhs) {
    const auto widen = [this](int y, double* out) {
      if (y < 0 || y >= height_) {
        std::fill_n(out, rowFloats_, 0.0);
        return;
      }
      const float* u = row(y);  // pairs: the grid row's padding supplies a zero when 3W is odd
      for (std::size_t j = 0; j < rowFloats_; j += 2) storeLanes(out + j, loadWidened(u + j));
    };
    double* up = widened_.data() + 3;
    double* centre = up + widenedStride_;
    double* down = centre + widenedStride_;
    widen(-1, up);
    widen(0, centre);
    DoubleLanes residualSquared = {0, 0};
    DoubleLanes rhsSquared = {0, 0};
    for (int y = 0; y < height_; ++y) {
      widen(y + 1, down);
      const float* b = rhs.data() + y * rowFloats_;
      const double degree = 2 + (y > 0) + (y + 1 < height_);
      // Pairs; when 3W is odd the last pair takes one zero past the row and a zero rhs.
      for (std::size_t j = 0; j < rowFloats_; j += 2) {
        const DoubleLanes bj = j + 1 < rowFloats_ ? loadWidened(b + j) : DoubleLanes{b[j], 0.0};
        const DoubleLanes r = bj - degree * loadLanes(centre + j) + loadLanes(centre + j - 3) +
                              loadLanes(centre + j + 3) + loadLanes(up + j) + loadLanes(down + j);
        residualSquared += r * r;
        rhsSquared += bj * bj;
      }
      std::swap(up, centre);
      std::swap(centre, down);
    }
    const double r2 = residualSquared[0] + residualSquared[1];
    const double b2 = rhsSquared[0] + rhsSquared[1];
    return std::sqrt(b2 > 0 ? r2 / b2 : r2);
  }

  int width_;
  int height_;
  std::size_t rowFloats_;  // 3 W
  std::size_t stride_;     // floats per grid row
  ColumnDct dct_;
  std::vector<float> grid_;          // H rows of stride_ floats (see row())
  std::vector<float> inversePivot_;  // 1 / d_x for frequency k at [x * height_ + k]
  std::size_t widenedStride_;        // 3 zeros, 3 W values, 4 zeros
  std::vector<double> widened_;      // the residual's three rows in double
};

}  // namespace

std::string rectangleSolverMismatch(const PoissonSystem& system) {
  const int width = system.size.width;
  const int height = system.size.height;
  const std::size_t n = system.unknowns();
  if (width < 1 || height < 1 || n != static_cast<std::size_t>(width) * height) {
    return fmt::format("{} unknowns do not fill the region's {}x{} frame", n, width, height);
  }
  if (system.degree.size() != n) return "the system has a degree count that does not match";
  for (std::size_t i = 0; i < n; ++i) {
    const cv::Point p = system.pixels[i];
    if (p.x != static_cast<int>(i % width) || p.y != static_cast<int>(i / width)) {
      return fmt::format("the unknowns are not the {}x{} rectangle in row-major order", width,
                         height);
    }
    const int unknownNeighbours = (p.x > 0) + (p.x < width - 1) + (p.y > 0) + (p.y < height - 1);
    const int dirichlet = system.degree[i] - unknownNeighbours;
    const int expected = (p.x == 0) + (p.x == width - 1);
    if (dirichlet == expected) continue;
    if (dirichlet < expected) {
      return fmt::format(
          "row {} of {} has no seam (Dirichlet neighbour) on its {} side; the rectangle solver "
          "needs seams along the whole left and right columns",
          p.y, height, width == 1 ? "left or right" : (p.x == 0 ? "left" : "right"));
    }
    return fmt::format(
        "pixel ({}, {}) has a Dirichlet neighbour above or below; the rectangle solver needs "
        "Neumann borders at top and bottom",
        p.x, p.y);
  }
  return {};
}

std::unique_ptr<PoissonSolver> makeRectangleSolver(const PoissonSystem& system) {
  if (const std::string mismatch = rectangleSolverMismatch(system); !mismatch.empty()) {
    throw std::invalid_argument("rectangle Poisson solver: " + mismatch);
  }
  const PoissonMatrix check(system);  // links and degrees consistent
  return std::make_unique<RectangleSolver>(system);
}

}  // namespace surroundd::processing
