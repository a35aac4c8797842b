#pragma once
// Geometric multigrid on a PoissonSystem's own pixel grid: one V-cycle approximates A^-1 r. The
// iterative solver uses it as the preconditioner of conjugate gradients.
//
// Level 0 is the region's frame plus a border of zeros; a frame pixel that is not an unknown is
// a hole that stays zero. Level l+1 keeps every other node of level l in each direction
// (vertex-centred, w / 2 + 1 nodes across); the transfers are bilinear interpolation P, restricted
// to the nodes that exist, and its transpose; each coarse matrix is the Galerkin product P^T A P
// (a 9-point stencil), so Dirichlet and Neumann borders and holes carry over to every level
// without special cases. Smoothing is damped Jacobi, as many sweeps after the coarse correction
// as before, so the V-cycle is a symmetric operator (what CG needs). The coarsest level is solved
// exactly by a dense Cholesky factor.
//
// Channels go through one at a time. Set up once; vcycle() allocates nothing.

#include <array>
#include <cstddef>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/colour/float_lanes.hpp"
#include "processing/colour/poisson_system.hpp"

namespace surroundd::processing {

class PoissonMultigrid {
 public:
  // The system must be consistent (PoissonMatrix checks that).
  explicit PoissonMultigrid(const PoissonSystem& system);

  // Level 0's layout: pixel (x, y) of the region's frame at (y + 1) * stride() + x + 1, in
  // arrays of gridSize() values that are zero wherever there is no unknown.
  int stride() const { return levels_.front().stride; }
  std::size_t gridSize() const { return levels_.front().cells; }
  std::size_t cellOf(cv::Point pixel) const {
    return static_cast<std::size_t>(pixel.y + 1) * stride() + pixel.x + 1;
  }

  // z ~ A^-1 r: `residual` on level 0's layout, zero off the region; returns z (same layout, zero
  // off the region), valid until the next call.
  const float* vcycle(const float* residual);

 private:
  struct Level {
    int width = 0;   // nodes across
    int height = 0;  // nodes down
    int stride = 0;  // floats per row, with a border and room for 4-lane loops to run over
    std::size_t cells = 0;
    std::vector<float> node;                    // 1 where a node exists, else 0
    std::vector<float> inverseDiagonal;         // damping / diagonal at nodes, else 0
    std::vector<float> degree;                  // level 0: the 5-point matrix's diagonal
    std::array<std::vector<float>, 9> stencil;  // levels >= 1: entry to neighbour (dx, dy) at
                                                // [(dy + 1) * 3 + dx + 1]
    std::vector<float> rhs;  // unused on level 0, whose right-hand side is the caller's
    std::vector<float> solution;
    std::vector<float> spare;  // Jacobi writes the next iterate here, then swaps
    std::vector<float> residual;
    std::size_t cell(int x, int y) const {
      return static_cast<std::size_t>(y + 1) * stride + x + 1;
    }
  };

  static Level makeLevel(int width, int height);
  static Level coarsen(const Level& fine);
  void factorCoarsest();
  void cycle(std::size_t l, const float* rhs);
  static void computeResidual(Level& level, const float* rhs);
  static void jacobiSweep(Level& level, const float* rhs);
  // The row loops, specialized for level 0 (5-point, masked) and the coarse levels (9-point).
  template <bool kFinest>
  class RowOperator;
  template <bool kFinest, bool kJacobi>
  static void rowPass(Level& level, const float* rhs);
  void restrictResidual(const Level& fine, Level& coarse);
  void prolongAndCorrect(const Level& coarse, Level& fine);
  void solveCoarsest(Level& level, const float* rhs);

  std::vector<Level> levels_;
  std::vector<float> rowBuffers_;  // transfers: three rows of the finest grid
  // The coarsest level as a dense Cholesky factor over its nodes (row-major, lower), in double.
  std::vector<std::size_t> coarsestCells_;
  std::vector<double> coarsestFactor_;
  std::vector<double> coarsestValues_;
};

}  // namespace surroundd::processing
