// The direct solver: SuiteSparse CHOLMOD's sparse Cholesky, analysed (fill-reducing ordering) and
// factored once; per frame one forward and back substitution with the three right-hand sides.

#include <algorithm>
#include <memory>
#include <stdexcept>

#include <cholmod.h>
#include <fmt/format.h>

#include "processing/colour/poisson_matrix.hpp"
#include "processing/colour/poisson_solver.hpp"

namespace surroundd::processing {
namespace {

// cholmod_start / cholmod_finish. Every CHOLMOD object is freed with the common it was made
// with, so the common is declared before (destroyed after) everything that uses it.
class CholmodCommon {
 public:
  CholmodCommon() {
    cholmod_start(&common_);
    common_.print = 0;  // errors become exceptions here, not lines on stdout
    // Simplicial, not supernodal: with Debian's reference BLAS the supernodal factor of these
    // grid matrices is 2-3 times slower to solve with (and to build), measured at 128x256 and
    // 512x256.
    common_.supernodal = CHOLMOD_SIMPLICIAL;
  }
  ~CholmodCommon() { cholmod_finish(&common_); }
  CholmodCommon(const CholmodCommon&) = delete;
  CholmodCommon& operator=(const CholmodCommon&) = delete;

  cholmod_common* get() { return &common_; }

 private:
  cholmod_common common_{};
};

struct CholmodDeleter {
  cholmod_common* common = nullptr;
  void operator()(cholmod_sparse* a) const { cholmod_free_sparse(&a, common); }
  void operator()(cholmod_factor* f) const { cholmod_free_factor(&f, common); }
  void operator()(cholmod_dense* d) const { cholmod_free_dense(&d, common); }
};
template <typename T>
using CholmodPtr = std::unique_ptr<T, CholmodDeleter>;

// cholmod_solve2's solution and workspace. It allocates them on its first call and reallocates
// them through these handles only when their size does not fit, so they are plain pointers here.
struct SolveBuffers {
  cholmod_common* common = nullptr;
  cholmod_dense* solution = nullptr;
  cholmod_dense* workspaceY = nullptr;
  cholmod_dense* workspaceE = nullptr;

  explicit SolveBuffers(cholmod_common* c) : common(c) {}
  ~SolveBuffers() {
    for (cholmod_dense** buffer : {&solution, &workspaceY, &workspaceE}) {
      cholmod_free_dense(buffer, common);
    }
  }
  SolveBuffers(const SolveBuffers&) = delete;
  SolveBuffers& operator=(const SolveBuffers&) = delete;
};

// Right-hand sides handed to CHOLMOD: the three channels and a column of zeros. Its simplicial
// solve works on 4 columns at a time, and with fewer it shrinks its workspace to that count on
// each call, which makes the next call allocate it again (2 allocations a solve). The zero column
// is the price of allocating nothing per frame: 3 columns take a quarter to a third less time
// (22272 unknowns: 1.2 against 1.8 ms; 5568: 0.17 against 0.22 ms).
constexpr std::size_t kColumns = 4;

// The lower triangle of A in compressed columns (CHOLMOD's stype -1): per column the degree on
// the diagonal, then -1 for each neighbour with a larger index.
//
// Written here, not through Eigen's CholmodSupport (an Eigen::SparseMatrix viewed by CHOLMOD and
// CholmodSimplicialLDLT / CholmodSupernodalLLT), which was measured against it on one core of the
// 2-core desk machine (surround-bench colour, 5 alternating rounds; and each step alone):
//   - Eigen's matrix takes 4 times as long to assemble (a 128x174 grid, 22272 unknowns: 0.50 ms
//     with setFromTriplets, 0.42 ms reserved and inserted in order, 0.11 ms here; all under 2 %
//     of the analysis and factorization, 25 ms);
//   - its solve() calls cholmod_solve, which allocates the solution and the workspace on every
//     call (4 allocations a frame; PoissonSolver.SolveAllocatesNothing fails); its simplicial
//     solve (22272 unknowns: 1.6 against 1.8 ms) wins only by solving 3 columns, not 4 (above);
//   - CholmodSupernodalLLT is 2-3.5 times slower to set up and to solve, as the common's note
//     says (the front regions of the 1080p and 480p benchmark recordings, 20826 and 5198
//     unknowns: set-up 129 and 19 ms against 47 and 8 ms, warm solve 4.2 and 1.0 ms against 2.1
//     and 0.30 ms).
CholmodPtr<cholmod_sparse> assembleLower(const PoissonMatrix& matrix, cholmod_common* common) {
  const std::size_t n = matrix.unknowns();
  std::size_t entries = n;
  for (std::size_t j = 0; j < n; ++j) {
    entries += static_cast<std::size_t>(std::ranges::count_if(
        matrix.neighbours(j), [j](std::int32_t i) { return static_cast<std::size_t>(i) > j; }));
  }
  CholmodPtr<cholmod_sparse> a(cholmod_allocate_sparse(n, n, entries, /*sorted=*/1, /*packed=*/1,
                                                       /*stype=*/-1, CHOLMOD_REAL, common),
                               CholmodDeleter{common});
  if (!a) throw std::runtime_error("CHOLMOD: out of memory for the Poisson matrix");
  auto* columnBegin = static_cast<int*>(a->p);
  auto* rows = static_cast<int*>(a->i);
  auto* values = static_cast<double*>(a->x);
  int k = 0;
  for (std::size_t j = 0; j < n; ++j) {
    columnBegin[j] = k;
    rows[k] = static_cast<int>(j);
    values[k++] = matrix.degree(j);
    for (const std::int32_t i : matrix.neighbours(j)) {  // increasing: the column stays sorted
      if (static_cast<std::size_t>(i) <= j) continue;
      rows[k] = i;
      values[k++] = -1.0;
    }
  }
  columnBegin[n] = k;
  return a;
}

class CholmodSolver final : public PoissonSolver {
 public:
  explicit CholmodSolver(const PoissonSystem& system)
      : matrix_(system), n_(matrix_.unknowns()), deleter_{common_.get()} {
    if (const auto floating = matrix_.floatingUnknown()) {
      throw std::runtime_error(fmt::format(
          "CHOLMOD: unknown {} is in a part of the region without a Dirichlet neighbour (the "
          "matrix is singular)",
          *floating));
    }
    cholmod_common* common = common_.get();
    const CholmodPtr<cholmod_sparse> a = assembleLower(matrix_, common);
    factor_ = CholmodPtr<cholmod_factor>(cholmod_analyze(a.get(), common), deleter_);
    if (!factor_) {
      throw std::runtime_error(fmt::format("CHOLMOD analysis failed (status {})", common->status));
    }
    cholmod_factorize(a.get(), factor_.get(), common);
    if (common->status == CHOLMOD_NOT_POSDEF) {
      throw std::runtime_error(fmt::format(
          "CHOLMOD: the Poisson matrix is not positive definite (from column {}): a part of the "
          "region has no Dirichlet neighbour",
          factor_->minor));
    }
    if (common->status != CHOLMOD_OK) {
      throw std::runtime_error(
          fmt::format("CHOLMOD factorization failed (status {})", common->status));
    }
    rhs_ = CholmodPtr<cholmod_dense>(cholmod_zeros(n_, kColumns, CHOLMOD_REAL, common), deleter_);
    if (!rhs_) throw std::runtime_error("CHOLMOD: out of memory for the right-hand sides");
    // cholmod_solve2 allocates its solution and workspace on the first call and reuses them
    // after: one solve here keeps solve() free of allocations.
    substitute();
  }

  PoissonSolverKind kind() const override { return PoissonSolverKind::kCholmod; }

  SolveStats solve(std::span<const float> rhs, std::span<float> x) override {
    checkChannelSpans(n_, rhs.size(), x.size());
    // CHOLMOD's dense matrices are column-major: one column per channel.
    auto* b = static_cast<double*>(rhs_->x);
    for (std::size_t i = 0; i < n_; ++i) {
      for (std::size_t c = 0; c < 3; ++c) b[c * n_ + i] = rhs[3 * i + c];
    }
    substitute();
    const auto* solution = static_cast<const double*>(buffers_.solution->x);
    for (std::size_t i = 0; i < n_; ++i) {
      for (std::size_t c = 0; c < 3; ++c) x[3 * i + c] = static_cast<float>(solution[c * n_ + i]);
    }
    return {0, matrix_.relativeResidual(rhs, x)};
  }

 private:
  void substitute() {
    if (!cholmod_solve2(CHOLMOD_A, factor_.get(), rhs_.get(), nullptr, &buffers_.solution, nullptr,
                        &buffers_.workspaceY, &buffers_.workspaceE, common_.get())) {
      // Only memory can run out here, and the buffers were allocated by the first call.
      throw std::runtime_error(
          fmt::format("CHOLMOD solve failed (status {})", common_.get()->status));
    }
  }

  CholmodCommon common_;
  PoissonMatrix matrix_;
  std::size_t n_;
  CholmodDeleter deleter_;
  CholmodPtr<cholmod_factor> factor_{nullptr, deleter_};
  CholmodPtr<cholmod_dense> rhs_{nullptr, deleter_};
  SolveBuffers buffers_{common_.get()};
};

}  // namespace

std::unique_ptr<PoissonSolver> makeCholmodSolver(const PoissonSystem& system) {
  return std::make_unique<CholmodSolver>(system);
}

}  // namespace surroundd::processing
