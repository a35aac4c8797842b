#include "processing/poisson_solver.hpp"

#include <fmt/format.h>

namespace surroundd::processing {

std::string_view poissonSolverName(PoissonSolverKind kind) {
  switch (kind) {
    case PoissonSolverKind::kAuto:
      return "auto";
    case PoissonSolverKind::kCholmod:
      return "cholmod";
    case PoissonSolverKind::kIterative:
      return "iterative";
    case PoissonSolverKind::kRectangle:
      return "rectangle";
  }
  return "unknown";
}

std::unique_ptr<PoissonSolver> makePoissonSolver(PoissonSolverKind kind,
                                                 const PoissonSystem& system, double tolerance) {
  switch (kind) {
    case PoissonSolverKind::kCholmod:
      return makeCholmodSolver(system);
    case PoissonSolverKind::kIterative:
      return makeIterativeSolver(system, tolerance);
    case PoissonSolverKind::kRectangle:
    case PoissonSolverKind::kAuto:
      break;
  }
  // The rectangle solver where it applies (exact, and the fastest); the iterative one elsewhere.
  const std::string mismatch = rectangleSolverMismatch(system);
  if (mismatch.empty()) return makeRectangleSolver(system);
  std::unique_ptr<PoissonSolver> solver = makeIterativeSolver(system, tolerance);
  solver->selectionNote_ =
      kind == PoissonSolverKind::kRectangle
          ? fmt::format("rectangle solver asked for, but {}: using the iterative solver", mismatch)
          : fmt::format("{}: auto uses the iterative solver", mismatch);
  return solver;
}

}  // namespace surroundd::processing
