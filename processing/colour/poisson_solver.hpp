#pragma once
// Solvers for the linear system of Poisson local colour correction (DESIGN.md §2.3).
//
// A solver is built once per region (ordering and factorization, multigrid hierarchy, transform
// work buffers); solve() is the per-frame call: three right-hand sides (the colour channels) in,
// three solutions out, nothing allocated. Two kinds:
//   cholmod    sparse Cholesky (SuiteSparse CHOLMOD), factored once; exact; any region.
//   iterative  conjugate gradients preconditioned by a geometric multigrid V-cycle on the region's
//              pixel grid, started from the previous frame's solution; any region.
// auto takes CHOLMOD below 6000 unknowns and the iterative solver above: measured on one core of
// the 2-core desk machine (tools/bench/poisson_benchmark), per frame at 128x256 and 512x256,
// CHOLMOD 2.6 / 19 ms, iterative (1e-4, warm) 1.6 / 6.7 ms.
// (A DCT solver for regions that fill a rectangle was here once; the regions real rigs give never
// do — body masks and floor-only seams cut them — so it went.)

#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "processing/colour/poisson_system.hpp"

namespace surroundd::processing {

enum class PoissonSolverKind { kAuto, kCholmod, kIterative };

// "auto", "cholmod", "iterative": the config's words.
std::string_view poissonSolverName(PoissonSolverKind kind);

struct SolveStats {
  int iterations = 0;             // V-cycles (the most any channel needed); 0 for direct solvers
  double relativeResidual = 0.0;  // |b - A x| / |b| over all channels on return; |A x| if b = 0
};

class PoissonSolver;

// Builds the solver of `kind` for `system` (it keeps what it needs: the system may go after this
// returns). `tolerance` is the relative residual at which the iterative solver stops (1e-4 keeps
// the field of a compact region within 0.01 levels of the exact one); CHOLMOD is exact. Throws
// std::invalid_argument for an inconsistent system and std::runtime_error when the matrix is not
// positive definite (a part of the region without a Dirichlet neighbour).
std::unique_ptr<PoissonSolver> makePoissonSolver(PoissonSolverKind kind,
                                                 const PoissonSystem& system, double tolerance);

class PoissonSolver {
 public:
  virtual ~PoissonSolver() = default;
  PoissonSolver(const PoissonSolver&) = delete;
  PoissonSolver& operator=(const PoissonSolver&) = delete;

  // rhs and x: 3 values per unknown, interleaved (index 3 * i + c), as ChannelValues. On entry x
  // holds the previous frame's solution (zeros the first time): the iterative solver starts from
  // it, the direct ones overwrite it. Allocates nothing. Throws std::invalid_argument when a span
  // does not have 3 values per unknown (a wiring error, caught by the first frame).
  virtual SolveStats solve(std::span<const float> rhs, std::span<float> x) = 0;

  virtual PoissonSolverKind kind() const = 0;
  std::string_view name() const { return poissonSolverName(kind()); }

  // Why auto built this kind; empty otherwise. For the log, once.
  const std::string& selectionNote() const { return selectionNote_; }

 protected:
  PoissonSolver() = default;

 private:
  friend std::unique_ptr<PoissonSolver> makePoissonSolver(PoissonSolverKind kind,
                                                          const PoissonSystem& system,
                                                          double tolerance);
  std::string selectionNote_;
};

// The solvers one by one (the factory's parts), with the same contract as makePoissonSolver.
std::unique_ptr<PoissonSolver> makeCholmodSolver(const PoissonSystem& system);
std::unique_ptr<PoissonSolver> makeIterativeSolver(const PoissonSystem& system, double tolerance);

}  // namespace surroundd::processing
