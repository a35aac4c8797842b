#include "processing/colour/poisson_multigrid.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "processing/colour/float_lanes.hpp"

namespace surroundd::processing {
namespace {

// Jacobi sweeps before and after the coarse correction.
constexpr int kSweeps = 2;
// Damping: 4/5 is the classic choice for the 5-point Laplacian (smoothing factor 0.6 a sweep);
// the Galerkin 9-point stencils smooth best undamped (1/3 a sweep in the interior), a little
// damping keeps nodes next to holes and borders safe.
constexpr float kFineDamping = 0.8f;
constexpr float kCoarseDamping = 0.9f;
// Coarsening stops at this many nodes; the dense factor then costs nodes^2 per solve.
constexpr std::size_t kCoarsestNodes = 100;
constexpr int kMaxLevels = 16;

// Stencil slot of neighbour (dx, dy), both in -1..1.
constexpr int slotOf(int dx, int dy) { return (dy + 1) * 3 + dx + 1; }

struct Parent {
  int index;  // coarse coordinate along one axis
  double weight;
};
// The coarse nodes along one axis that interpolate fine coordinate x (bilinear: the node on top
// of it, or the two beside it).
int parentsOf(int x, std::array<Parent, 2>& parents) {
  if (x % 2 == 0) {
    parents[0] = {x / 2, 1.0};
    return 1;
  }
  parents[0] = {(x - 1) / 2, 0.5};
  parents[1] = {(x + 1) / 2, 0.5};
  return 2;
}

}  // namespace

PoissonMultigrid::PoissonMultigrid(const PoissonSystem& system) {
  // Level 0: the 5-point matrix; its stencil planes serve only to build the coarse levels.
  Level fine = makeLevel(system.size.width, system.size.height);
  fine.degree.assign(fine.cells, 0.0f);
  for (std::size_t i = 0; i < system.unknowns(); ++i) {
    const std::size_t c = fine.cell(system.pixels[i].x, system.pixels[i].y);
    fine.node[c] = 1;
    fine.degree[c] = static_cast<float>(system.degree[i]);
    fine.stencil[slotOf(0, 0)][c] = fine.degree[c];
    fine.inverseDiagonal[c] = kFineDamping / fine.degree[c];
  }
  const auto fineStride = static_cast<std::ptrdiff_t>(fine.stride);
  for (std::size_t c = 0; c < fine.cells; ++c) {
    if (fine.node[c] == 0) continue;
    for (const auto& [dx, dy] :
         {std::pair{-1, 0}, std::pair{1, 0}, std::pair{0, -1}, std::pair{0, 1}}) {
      if (fine.node[c + dx + dy * fineStride] != 0) fine.stencil[slotOf(dx, dy)][c] = -1;
    }
  }
  levels_.push_back(std::move(fine));

  // Coarse levels until few nodes are left (or the grid stops shrinking).
  std::size_t nodes = system.unknowns();
  while (nodes > kCoarsestNodes && static_cast<int>(levels_.size()) < kMaxLevels) {
    const Level& from = levels_.back();
    if (from.width / 2 + 1 >= from.width && from.height / 2 + 1 >= from.height) break;
    levels_.push_back(coarsen(from));
    const auto& node = levels_.back().node;
    nodes = static_cast<std::size_t>(std::count(node.begin(), node.end(), 1.0f));
  }
  factorCoarsest();

  // Level 0 smooths with its degrees; its stencil planes are no longer needed.
  if (levels_.size() > 1) {
    for (auto& plane : levels_.front().stencil) std::vector<float>().swap(plane);
  }
  rowBuffers_.assign(3 * static_cast<std::size_t>(levels_.front().stride), 0.0f);
}

PoissonMultigrid::Level PoissonMultigrid::makeLevel(int width, int height) {
  Level level;
  level.width = width;
  level.height = height;
  // A border of one cell each side, room for restriction to read one cell past the last
  // (x = w + 1), and for 4-lane loops to overrun the row end by up to 3 plus a neighbour.
  level.stride = (width + 5 + 3) / 4 * 4;
  level.cells = static_cast<std::size_t>(level.stride) * (height + 3);
  for (auto* plane : {&level.node, &level.inverseDiagonal, &level.rhs, &level.solution,
                      &level.spare, &level.residual}) {
    plane->assign(level.cells, 0.0f);
  }
  for (auto& plane : level.stencil) plane.assign(level.cells, 0.0f);
  return level;
}

// The next level: every other node, its matrix P^T A P.
PoissonMultigrid::Level PoissonMultigrid::coarsen(const Level& fine) {
  Level coarse = makeLevel(fine.width / 2 + 1, fine.height / 2 + 1);
  std::array<std::vector<double>, 9> sums;
  for (auto& plane : sums) plane.assign(coarse.cells, 0.0);
  std::array<Parent, 2> px{}, py{}, qx{}, qy{};
  for (int y = 0; y < fine.height; ++y) {
    for (int x = 0; x < fine.width; ++x) {
      const std::size_t p = fine.cell(x, y);
      if (fine.node[p] == 0) continue;
      const int npx = parentsOf(x, px);
      const int npy = parentsOf(y, py);
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const double entry = fine.stencil[slotOf(dx, dy)][p];
          if (entry == 0) continue;
          const int nqx = parentsOf(x + dx, qx);
          const int nqy = parentsOf(y + dy, qy);
          // (P^T A P)_IJ gathers w_pI a_pq w_qJ over the parents I of p and J of q.
          for (int a = 0; a < npy; ++a) {
            for (int b = 0; b < npx; ++b) {
              const std::size_t coarseCell = coarse.cell(px[b].index, py[a].index);
              const double left = px[b].weight * py[a].weight * entry;
              for (int c = 0; c < nqy; ++c) {
                for (int d = 0; d < nqx; ++d) {
                  sums[slotOf(qx[d].index - px[b].index, qy[c].index - py[a].index)][coarseCell] +=
                      left * qx[d].weight * qy[c].weight;
                }
              }
            }
          }
        }
      }
    }
  }
  // A coarse node exists where some fine node interpolates from it: its diagonal is then
  // p^T A p > 0 for its (nonzero) interpolation column p.
  for (std::size_t c = 0; c < coarse.cells; ++c) {
    for (std::size_t s = 0; s < sums.size(); ++s) {
      coarse.stencil[s][c] = static_cast<float>(sums[s][c]);
    }
    const float diagonal = coarse.stencil[slotOf(0, 0)][c];
    if (diagonal <= 0) continue;
    coarse.node[c] = 1;
    coarse.inverseDiagonal[c] = kCoarseDamping / diagonal;
  }
  return coarse;
}

// The coarsest level's dense Cholesky factor. A Galerkin matrix can be singular where two coarse
// nodes interpolate to the same single fine node; a pivot that vanishes drops its node (solution
// 0 there), which still solves the consistent systems that restriction produces.
void PoissonMultigrid::factorCoarsest() {
  const Level& last = levels_.back();
  std::vector<int> indexOfCell(last.cells, -1);
  for (std::size_t c = 0; c < last.cells; ++c) {
    if (last.node[c] == 0) continue;
    indexOfCell[c] = static_cast<int>(coarsestCells_.size());
    coarsestCells_.push_back(c);
  }
  const std::size_t m = coarsestCells_.size();
  coarsestFactor_.assign(m * m, 0.0);
  coarsestValues_.assign(m, 0.0);
  const auto stride = static_cast<std::ptrdiff_t>(last.stride);
  double largestDiagonal = 0;
  for (std::size_t k = 0; k < m; ++k) {  // the lower triangle of the matrix
    const std::size_t c = coarsestCells_[k];
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const float entry = last.stencil[slotOf(dx, dy)][c];
        const int other = entry == 0 ? -1 : indexOfCell[c + dx + dy * stride];
        if (other >= 0 && static_cast<std::size_t>(other) <= k) {
          coarsestFactor_[k * m + static_cast<std::size_t>(other)] = entry;
        }
      }
    }
    largestDiagonal = std::max(largestDiagonal, coarsestFactor_[k * m + k]);
  }
  for (std::size_t j = 0; j < m; ++j) {
    double* rowJ = coarsestFactor_.data() + j * m;
    double pivot = rowJ[j];
    for (std::size_t k = 0; k < j; ++k) pivot -= rowJ[k] * rowJ[k];
    if (pivot <= 1e-9 * largestDiagonal) {
      std::fill(rowJ, rowJ + j + 1, 0.0);
      for (std::size_t i = j + 1; i < m; ++i) coarsestFactor_[i * m + j] = 0;
      continue;
    }
    rowJ[j] = std::sqrt(pivot);
    for (std::size_t i = j + 1; i < m; ++i) {
      double* rowI = coarsestFactor_.data() + i * m;
      double sum = rowI[j];
      for (std::size_t k = 0; k < j; ++k) sum -= rowI[k] * rowJ[k];
      rowI[j] = sum / rowJ[j];
    }
  }
}

const float* PoissonMultigrid::vcycle(const float* residual) {
  cycle(0, residual);
  return levels_.front().solution.data();
}

void PoissonMultigrid::cycle(std::size_t l, const float* rhs) {
  Level& level = levels_[l];
  if (l + 1 == levels_.size()) {
    solveCoarsest(level, rhs);
    return;
  }
  // The first sweep starts from zero: u = D^-1 f.
  for (std::size_t c = 0; c < level.cells; c += kFloatLanes) {
    storeLanes(level.solution.data() + c,
               loadLanes(level.inverseDiagonal.data() + c) * loadLanes(rhs + c));
  }
  for (int sweep = 1; sweep < kSweeps; ++sweep) jacobiSweep(level, rhs);
  computeResidual(level, rhs);
  Level& coarse = levels_[l + 1];
  restrictResidual(level, coarse);
  cycle(l + 1, coarse.rhs.data());
  prolongAndCorrect(coarse, level);
  for (int sweep = 0; sweep < kSweeps; ++sweep) jacobiSweep(level, rhs);
}

// (A u) at the four cells from x on in row y of a level: level 0's 5-point matrix (degree on the
// diagonal, -1 to each neighbour; holes hold zero, so the plain sum of the neighbours is right),
// or a coarse level's 9-point stencil (zero in every slot off the nodes). The per-row pointers
// are set up once per row so that the per-cell work is loads and arithmetic only.
template <bool kFinest>
class PoissonMultigrid::RowOperator {
 public:
  RowOperator(const Level& level, const float* u, int y)
      : begin_(level.cell(0, y)),
        stride_(static_cast<std::ptrdiff_t>(level.stride)),
        centre_(u + begin_) {
    if constexpr (kFinest) {
      degree_ = level.degree.data() + begin_;
    } else {
      for (std::size_t s = 0; s < stencil_.size(); ++s)
        stencil_[s] = level.stencil[s].data() + begin_;
    }
  }
  std::size_t begin() const { return begin_; }

  FloatLanes at(int x) const {
    const float* u = centre_ + x;
    if constexpr (kFinest) {
      return loadLanes(degree_ + x) * loadLanes(u) -
             (loadLanes(u - 1) + loadLanes(u + 1) + loadLanes(u - stride_) +
              loadLanes(u + stride_));
    } else {
      const float* up = u - stride_;
      const float* down = u + stride_;
      return loadLanes(stencil_[0] + x) * loadLanes(up - 1) +
             loadLanes(stencil_[1] + x) * loadLanes(up) +
             loadLanes(stencil_[2] + x) * loadLanes(up + 1) +
             loadLanes(stencil_[3] + x) * loadLanes(u - 1) +
             loadLanes(stencil_[4] + x) * loadLanes(u) +
             loadLanes(stencil_[5] + x) * loadLanes(u + 1) +
             loadLanes(stencil_[6] + x) * loadLanes(down - 1) +
             loadLanes(stencil_[7] + x) * loadLanes(down) +
             loadLanes(stencil_[8] + x) * loadLanes(down + 1);
    }
  }

 private:
  std::size_t begin_;
  std::ptrdiff_t stride_;
  const float* centre_;
  const float* degree_ = nullptr;
  std::array<const float*, 9> stencil_{};
};

// One pass over the rows of a level: the residual r = f - A u (zero off the nodes: level 0
// masks it, coarse levels have f = 0 and empty stencils there), or a damped Jacobi sweep
// u' = u + w D^-1 (f - A u) into the spare plane, which then becomes the solution (w D^-1 is zero
// off the nodes, so they stay zero).
template <bool kFinest, bool kJacobi>
void PoissonMultigrid::rowPass(Level& level, const float* f) {
  float* out = kJacobi ? level.spare.data() : level.residual.data();
  for (int y = 0; y < level.height; ++y) {
    const RowOperator<kFinest> a(level, level.solution.data(), y);
    const std::size_t begin = a.begin();
    for (int x = 0; x < level.width; x += kFloatLanes) {
      const std::size_t at = begin + x;
      const FloatLanes r = loadLanes(f + at) - a.at(x);
      if constexpr (kJacobi) {
        storeLanes(out + at, loadLanes(level.solution.data() + at) +
                                 loadLanes(level.inverseDiagonal.data() + at) * r);
      } else if constexpr (kFinest) {
        storeLanes(out + at, loadLanes(level.node.data() + at) * r);
      } else {
        storeLanes(out + at, r);
      }
    }
  }
  if constexpr (kJacobi) level.solution.swap(level.spare);
}

void PoissonMultigrid::computeResidual(Level& level, const float* rhs) {
  level.degree.empty() ? rowPass<false, false>(level, rhs) : rowPass<true, false>(level, rhs);
}

void PoissonMultigrid::jacobiSweep(Level& level, const float* rhs) {
  level.degree.empty() ? rowPass<false, true>(level, rhs) : rowPass<true, true>(level, rhs);
}

// f_coarse = P^T r: the full-weighting stencil (1/4 1/2 1/4 by rows and columns, centre 1)
// around each coarse node's fine position (2I, 2J); first down the rows, then along them.
void PoissonMultigrid::restrictResidual(const Level& fine, Level& coarse) {
  float* combined = rowBuffers_.data();
  const auto stride = static_cast<std::size_t>(fine.stride);
  for (int j = 0; j < coarse.height; ++j) {
    const float* centre = fine.residual.data() + fine.cell(-1, 2 * j);
    for (std::size_t c = 0; c < stride; c += kFloatLanes) {
      storeLanes(combined + c, loadLanes(centre + c) + 0.5f * (loadLanes(centre + c - stride) +
                                                               loadLanes(centre + c + stride)));
    }
    float* f = coarse.rhs.data() + coarse.cell(0, j);
    for (int i = 0; i < coarse.width; ++i) {  // fine x = 2i sits at combined[2i + 1]
      const auto x = 2 * static_cast<std::size_t>(i);
      f[i] = combined[x + 1] + 0.5f * (combined[x] + combined[x + 2]);
    }
  }
}

// u_fine += P e_coarse at the fine nodes: each coarse row interpolated along x, then rows
// 2J (that row) and 2J - 1 (the mean of rows J - 1 and J).
void PoissonMultigrid::prolongAndCorrect(const Level& coarse, Level& fine) {
  const auto stride = static_cast<std::size_t>(fine.stride);
  float* previous = rowBuffers_.data();
  float* current = previous + stride;
  for (int j = 0; j < coarse.height; ++j) {
    const float* e = coarse.solution.data() + coarse.cell(0, j);
    float* interpolated = current + 1;  // aligned with fine x = 0
    for (int x = 0; x < fine.width; ++x) {
      interpolated[x] = x % 2 == 0 ? e[x / 2] : 0.5f * (e[x / 2] + e[x / 2 + 1]);
    }
    const auto correct = [&](int y, bool between) {
      const std::size_t begin = fine.cell(0, y);
      float* u = fine.solution.data() + begin;
      const float* node = fine.node.data() + begin;
      for (int x = 0; x < fine.width; x += kFloatLanes) {
        const FloatLanes here = loadLanes(interpolated + x);
        const FloatLanes value = between ? 0.5f * (here + loadLanes(previous + 1 + x)) : here;
        storeLanes(u + x, loadLanes(u + x) + loadLanes(node + x) * value);
      }
    };
    if (2 * j < fine.height) correct(2 * j, false);
    if (j > 0 && 2 * j - 1 < fine.height) correct(2 * j - 1, true);
    std::swap(previous, current);
  }
}

void PoissonMultigrid::solveCoarsest(Level& level, const float* rhs) {
  const std::size_t m = coarsestCells_.size();
  const double* factor = coarsestFactor_.data();
  double* values = coarsestValues_.data();
  for (std::size_t k = 0; k < m; ++k) values[k] = rhs[coarsestCells_[k]];
  for (std::size_t j = 0; j < m; ++j) {  // L y = f
    const double* row = factor + j * m;
    double sum = values[j];
    for (std::size_t k = 0; k < j; ++k) sum -= row[k] * values[k];
    values[j] = row[j] > 0 ? sum / row[j] : 0.0;
  }
  for (std::size_t j = m; j-- > 0;) {  // L^T u = y
    double sum = values[j];
    for (std::size_t i = j + 1; i < m; ++i) sum -= factor[i * m + j] * values[i];
    values[j] = factor[j * m + j] > 0 ? sum / factor[j * m + j] : 0.0;
  }
  for (std::size_t k = 0; k < m; ++k) {
    level.solution[coarsestCells_[k]] = static_cast<float>(values[k]);
  }
}

}  // namespace surroundd::processing
