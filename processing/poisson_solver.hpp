#pragma once
// Solvers for the linear system of Poisson local colour correction (DESIGN.md §2.3).
//
// A solver is built once per region (ordering and factorization, multigrid hierarchy, transform
// tables, work buffers); solve() is the per-frame call: three right-hand sides (the colour
// channels) in, three solutions out, nothing allocated. Three kinds:
//   cholmod    sparse Cholesky (SuiteSparse CHOLMOD), factored once; exact; any region.
//   iterative  conjugate gradients preconditioned by a geometric multigrid V-cycle on the region's
//              pixel grid, started from the previous frame's solution; any region.
//   rectangle  exact and fastest, for the region that fixed-azimuth seams make: the unknowns fill
//              a full rectangle, seams (Dirichlet) along its left and right columns, Neumann at
//              top and bottom. A DCT along y separates it into tridiagonal systems along x.
// auto takes the rectangle solver where it applies, else CHOLMOD below 6000 unknowns and the
// iterative solver above: measured on one core of the 2-core desk machine
// (tools/bench/poisson_benchmark), per frame at 128x256 and 512x256, CHOLMOD 2.6 / 19 ms,
// iterative (1e-4, warm) 1.6 / 6.7 ms, rectangle 0.4 / 1.9 ms.

#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "processing/poisson_system.hpp"

namespace surroundd::processing {

enum class PoissonSolverKind { kAuto, kCholmod, kIterative, kRectangle };

// "auto", "cholmod", "iterative", "rectangle": the config's words.
std::string_view poissonSolverName(PoissonSolverKind kind);

struct SolveStats {
  int iterations = 0;             // V-cycles (the most any channel needed); 0 for direct solvers
  double relativeResidual = 0.0;  // |b - A x| / |b| over all channels on return; |A x| if b = 0
};

class PoissonSolver;

// Builds the solver of `kind` for `system` (it keeps what it needs: the system may go after this
// returns). `tolerance` is the relative residual at which the iterative solver stops (1e-4 keeps
// the field of a compact region within 0.01 levels of the exact one); the direct solvers are exact.
// kRectangle on a system that is not the rectangle falls back to what auto takes there, and
// selectionNote() says why. Throws std::invalid_argument for an inconsistent system and
// std::runtime_error when the matrix is not positive definite (a part of the region without a
// Dirichlet neighbour).
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

  // Why the factory built this kind: for auto, and for a rectangle request that fell back, what
  // ruled the rectangle solver out; empty otherwise. For the log, once.
  const std::string& selectionNote() const { return selectionNote_; }

 protected:
  PoissonSolver() = default;

 private:
  friend std::unique_ptr<PoissonSolver> makePoissonSolver(PoissonSolverKind kind,
                                                          const PoissonSystem& system,
                                                          double tolerance);
  std::string selectionNote_;
};

// Empty when the rectangle solver applies to `system`; otherwise why not, in one sentence.
std::string rectangleSolverMismatch(const PoissonSystem& system);

// The solvers one by one (the factory's parts), with the same contract as makePoissonSolver.
// makeRectangleSolver throws std::invalid_argument with rectangleSolverMismatch()'s reason where
// it does not apply.
std::unique_ptr<PoissonSolver> makeCholmodSolver(const PoissonSystem& system);
std::unique_ptr<PoissonSolver> makeIterativeSolver(const PoissonSystem& system, double tolerance);
std::unique_ptr<PoissonSolver> makeRectangleSolver(const PoissonSystem& system);

}  // namespace surroundd::processing
