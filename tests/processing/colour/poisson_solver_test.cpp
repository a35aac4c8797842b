// The Poisson solvers on systems drawn here: a rectangle with seams along two sides, a
// region with holes, an uneven bottom edge and rows without seams, and one with a part that no
// seam reaches. Every pair of solvers that applies agrees to 0.01 8-bit levels.

#include "processing/colour/poisson_solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <new>
#include <random>
#include <stdexcept>
#include <vector>

#include <SuiteSparse_config.h>
#include <gtest/gtest.h>

#include "processing/colour/poisson_matrix.hpp"
#include "tests/processing/colour/poisson_test_problems.hpp"

// Counts allocations while `countAllocations` is set: operator new here, malloc and friends in
// SuiteSparse through its hooks (CHOLMOD allocates through them).
namespace {
bool countAllocations = false;
int allocations = 0;
}  // namespace

// GCC sees free() meet operator new once these are inlined into the standard library's callers.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  if (countAllocations) ++allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace surroundd::processing {
namespace {

using testing::buildProblem;
using testing::Canvas;
using testing::Cell;
using testing::driftedRhs;
using testing::fillSeams;
using testing::irregularCanvas;
using testing::Problem;
using testing::rectangleCanvas;

constexpr double kTolerance = 1e-5;
constexpr float kAgreement = 0.01f;  // 8-bit levels

ChannelValues solveWith(PoissonSolverKind kind, const Problem& problem) {
  auto solver = makePoissonSolver(kind, problem.system, kTolerance);
  EXPECT_EQ(solver->kind(), kind);
  ChannelValues x(problem.rhs.size(), 0.0f);
  solver->solve(problem.rhs, x);
  return x;
}

float largestDifference(const ChannelValues& a, const ChannelValues& b) {
  float largest = 0;
  for (std::size_t i = 0; i < a.size(); ++i) largest = std::max(largest, std::abs(a[i] - b[i]));
  return largest;
}

class RectangleSizes : public ::testing::TestWithParam<cv::Size> {};

TEST_P(RectangleSizes, BothSolversAgree) {
  const Problem problem = buildProblem(rectangleCanvas(GetParam()));
  const ChannelValues cholmod = solveWith(PoissonSolverKind::kCholmod, problem);
  const ChannelValues iterative = solveWith(PoissonSolverKind::kIterative, problem);
  EXPECT_LE(largestDifference(cholmod, iterative), kAgreement);
  // The field stays within the seam values (maximum principle), so nothing blew up.
  for (const float value : cholmod) {
    EXPECT_GE(value, -0.01f);
    EXPECT_LE(value, 60.01f);
  }
}

INSTANTIATE_TEST_SUITE_P(PoissonSolver, RectangleSizes,
                         ::testing::Values(cv::Size(1, 1), cv::Size(2, 3), cv::Size(7, 5),
                                           cv::Size(33, 17), cv::Size(128, 180),
                                           cv::Size(512, 256)),
                         [](const auto& test) {
                           return std::to_string(test.param.width) + "x" +
                                  std::to_string(test.param.height);
                         });

TEST(PoissonSolver, CholmodLeavesOnlyFloatRounding) {
  const Problem problem = buildProblem(rectangleCanvas({128, 180}));
  auto solver = makePoissonSolver(PoissonSolverKind::kCholmod, problem.system, kTolerance);
  ChannelValues x(problem.rhs.size(), 0.0f);
  const SolveStats stats = solver->solve(problem.rhs, x);
  EXPECT_EQ(stats.iterations, 0);
  // The solution is returned in float: rounding it alone leaves a residual of about 1e-6.
  EXPECT_LT(stats.relativeResidual, 1e-5);
  EXPECT_NEAR(stats.relativeResidual,
              PoissonMatrix(problem.system).relativeResidual(problem.rhs, x), 1e-9);
}

TEST(PoissonSolver, IrregularRegionCholmodAndIterativeAgree) {
  const Problem problem = buildProblem(irregularCanvas({90, 40}));
  const ChannelValues cholmod = solveWith(PoissonSolverKind::kCholmod, problem);
  const ChannelValues iterative = solveWith(PoissonSolverKind::kIterative, problem);
  EXPECT_LE(largestDifference(cholmod, iterative), kAgreement);
}

TEST(PoissonSolver, ThinCorridorCholmodAndIterativeAgree) {
  // A seam at the end of a one-pixel corridor that leads into a room: the field is the seam's
  // value everywhere, and the matrix is badly conditioned (a residual that float arithmetic
  // would lose track of still moves the room by a level).
  Canvas canvas({300, 20}, Cell::kOutside);
  canvas.at(0, 10) = Cell::kDirichlet;
  for (int x = 1; x < 299; ++x) canvas.at(x, 10) = Cell::kUnknown;
  for (int y = 2; y < 18; ++y) {
    for (int x = 250; x < 299; ++x) canvas.at(x, y) = Cell::kUnknown;
  }
  fillSeams(canvas, 3);
  const Problem problem = buildProblem(canvas);
  const ChannelValues cholmod = solveWith(PoissonSolverKind::kCholmod, problem);
  const ChannelValues iterative = solveWith(PoissonSolverKind::kIterative, problem);
  EXPECT_LE(largestDifference(cholmod, iterative), kAgreement);
  const cv::Vec3f seam = canvas.values[canvas.index(0, 10)];
  for (std::size_t i = 0; i < cholmod.size(); ++i) {
    EXPECT_NEAR(cholmod[i], seam[static_cast<int>(i % 3)], 1e-3);
  }
}

TEST(PoissonSolver, IterativeResidualIsTheTrueOne) {
  const Problem problem = buildProblem(irregularCanvas({90, 40}));
  for (const double tolerance : {1e-3, 1e-4, 1e-5}) {
    auto solver = makeIterativeSolver(problem.system, tolerance);
    ChannelValues x(problem.rhs.size(), 0.0f);
    const SolveStats stats = solver->solve(problem.rhs, x);
    EXPECT_LE(stats.relativeResidual, tolerance);
    EXPECT_GT(stats.iterations, 0);
    const double trueResidual = PoissonMatrix(problem.system).relativeResidual(problem.rhs, x);
    EXPECT_NEAR(trueResidual, stats.relativeResidual, 0.1 * tolerance + 2e-6);
  }
}

TEST(PoissonSolver, PartWithoutSeamIsLeftOutByConstruction) {
  Canvas canvas = rectangleCanvas({40, 30});
  // An island of unknowns walled off from both seams: Neumann all round, so no solution is
  // defined there; the builder (like the domain builder) leaves it out.
  for (int y = 8; y < 20; ++y) {
    for (int x = 10; x < 24; ++x) {
      const bool wall = y == 8 || y == 19 || x == 10 || x == 23;
      canvas.at(x, y) = wall ? Cell::kOutside : Cell::kUnknown;
    }
  }
  const Problem problem = buildProblem(canvas);
  EXPECT_EQ(problem.leftOut, 10u * 12u);
  EXPECT_FALSE(PoissonMatrix(problem.system).floatingUnknown().has_value());
  const ChannelValues cholmod = solveWith(PoissonSolverKind::kCholmod, problem);
  const ChannelValues iterative = solveWith(PoissonSolverKind::kIterative, problem);
  EXPECT_LE(largestDifference(cholmod, iterative), kAgreement);
}

TEST(PoissonSolver, SingularSystemIsRefusedAtSetUp) {
  Canvas canvas({6, 4}, Cell::kUnknown);  // no seam anywhere: Neumann only
  Problem problem = buildProblem(canvas);
  ASSERT_EQ(problem.leftOut, 24u);
  // Built by hand, as a domain builder that forgot to leave the part out would.
  problem.system.size = {2, 1};
  problem.system.pixels = {{0, 0}, {1, 0}};
  problem.system.degree = {1, 1};
  problem.system.links = {{0, 1}};
  for (const auto kind : {PoissonSolverKind::kCholmod, PoissonSolverKind::kIterative}) {
    try {
      makePoissonSolver(kind, problem.system, kTolerance);
      ADD_FAILURE() << poissonSolverName(kind) << " accepted a singular system";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("without a Dirichlet neighbour"), std::string::npos)
          << e.what();
    }
  }
}

TEST(PoissonSolver, InconsistentSystemIsRefused) {
  Problem problem = buildProblem(rectangleCanvas({4, 3}));
  problem.system.links.pop_back();  // two neighbouring unknowns without their link
  EXPECT_THROW(makePoissonSolver(PoissonSolverKind::kAuto, problem.system, kTolerance),
               std::invalid_argument);
  EXPECT_THROW(makePoissonSolver(PoissonSolverKind::kCholmod, problem.system, kTolerance),
               std::invalid_argument);
}

TEST(PoissonSolver, IterativeStartsFromThePreviousSolution) {
  const Canvas canvas = irregularCanvas({128, 64});
  const Problem problem = buildProblem(canvas);
  // Seams 1% brighter with 0.2 levels of noise: the warm start is 100 times closer than zero;
  // a drift of 0.1% and 0.02 levels is closer to what one frame brings.
  const ChannelValues brighter = driftedRhs(canvas, 1.01f, 0.2f, 3);
  const ChannelValues drifted = driftedRhs(canvas, 1.001f, 0.02f, 4);
  // 1e-3 is the config's default; 1e-4 keeps the field within 0.01 levels of the exact one.
  for (const double tolerance : {1e-3, 1e-4}) {
    SCOPED_TRACE(tolerance);
    auto solver = makeIterativeSolver(problem.system, tolerance);
    ChannelValues previous(problem.rhs.size(), 0.0f);
    EXPECT_GT(solver->solve(problem.rhs, previous).iterations, 0);
    const auto iterations = [&](const ChannelValues& rhs, bool warm) {
      ChannelValues x = warm ? previous : ChannelValues(rhs.size(), 0.0f);
      return solver->solve(rhs, x).iterations;
    };
    // The same right-hand side again: already converged.
    EXPECT_EQ(iterations(problem.rhs, true), 0);
    // A V-cycle cuts the residual 20 to 50 times, so a cold start takes 3 to 4 iterations and the
    // 100 times closer start saves about half of them.
    const int cold = iterations(brighter, false);
    const int warm = iterations(brighter, true);
    EXPECT_LE(2 * warm, cold) << "cold " << cold << ", warm " << warm;
    if (tolerance >= 1e-3) {
      EXPECT_LE(3 * warm, cold) << "cold " << cold << ", warm " << warm;
    }
    const int coldDrift = iterations(drifted, false);
    const int warmDrift = iterations(drifted, true);
    EXPECT_LE(3 * warmDrift, coldDrift) << "cold " << coldDrift << ", warm " << warmDrift;
  }
}

TEST(PoissonSolver, AutoTakesTheFastestSolverThatApplies) {
  // Returns the unknowns, to check which side of the size threshold the region is.
  const auto expectAuto = [](const Canvas& canvas, PoissonSolverKind kind,
                             const std::string& note) {
    const Problem problem = buildProblem(canvas);
    const auto solver = makePoissonSolver(PoissonSolverKind::kAuto, problem.system, kTolerance);
    EXPECT_EQ(solver->kind(), kind);
    if (note.empty()) {
      EXPECT_EQ(solver->selectionNote(), "");
    } else {
      EXPECT_NE(solver->selectionNote().find(note), std::string::npos) << note;
    }
    return problem.system.unknowns();
  };
  EXPECT_LT(expectAuto(irregularCanvas({64, 48}), PoissonSolverKind::kCholmod, "auto uses CHOLMOD"),
            6000u);
  EXPECT_GE(expectAuto(irregularCanvas({160, 64}), PoissonSolverKind::kIterative,
                       "auto uses the iterative solver"),
            6000u);
}

TEST(PoissonSolver, SolveChecksSpanSizes) {
  const Problem problem = buildProblem(rectangleCanvas({5, 4}));
  for (const auto kind : {PoissonSolverKind::kCholmod, PoissonSolverKind::kIterative}) {
    auto solver = makePoissonSolver(kind, problem.system, kTolerance);
    ChannelValues x(problem.rhs.size() - 3, 0.0f);
    EXPECT_THROW(solver->solve(problem.rhs, x), std::invalid_argument);
  }
}

TEST(PoissonSolver, ZeroRightHandSideGivesZero) {
  const Problem problem = buildProblem(irregularCanvas({40, 30}));
  const ChannelValues zero(problem.rhs.size(), 0.0f);
  for (const auto kind : {PoissonSolverKind::kCholmod, PoissonSolverKind::kIterative}) {
    auto solver = makePoissonSolver(kind, problem.system, kTolerance);
    ChannelValues x(problem.rhs.size(), 5.0f);  // a stale start
    const SolveStats stats = solver->solve(zero, x);
    EXPECT_EQ(stats.relativeResidual, 0.0);
    EXPECT_EQ(largestDifference(x, zero), 0.0f) << solver->name();
  }
}

TEST(PoissonSolver, SolveAllocatesNothing) {
  const auto saved = SuiteSparse_config;
  SuiteSparse_config.malloc_func = [](std::size_t size) {
    if (countAllocations) ++allocations;
    return std::malloc(size);
  };
  SuiteSparse_config.calloc_func = [](std::size_t count, std::size_t size) {
    if (countAllocations) ++allocations;
    return std::calloc(count, size);
  };
  SuiteSparse_config.realloc_func = [](void* p, std::size_t size) {
    if (countAllocations) ++allocations;
    return std::realloc(p, size);
  };
  const Problem problem = buildProblem(irregularCanvas({48, 30}));
  for (const auto kind : {PoissonSolverKind::kCholmod, PoissonSolverKind::kIterative}) {
    auto solver = makePoissonSolver(kind, problem.system, kTolerance);
    ChannelValues x(problem.rhs.size(), 0.0f);
    allocations = 0;
    countAllocations = true;
    solver->solve(problem.rhs, x);
    solver->solve(problem.rhs, x);
    countAllocations = false;
    EXPECT_EQ(allocations, 0) << solver->name();
  }
  SuiteSparse_config = saved;
}

}  // namespace
}  // namespace surroundd::processing
