// Intrinsics from any board on generated pictures with known truth: square and oblong
// chessboards and ChArUco boards, seen whole or cut off at the image edge, through the paper
// rig's pinhole and the production rig's 190-degree fisheye, and fisheye pictures made harder
// (blur, noise, vignetting, cut-off boards). Focal lengths within 0.5 %, the principal point
// within 1 px, and a passing verdict.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "processing/calibration/calibration_coverage.hpp"
#include "processing/calibration/calibration_verdict.hpp"
#include "processing/calibration/view_acceptance.hpp"
#include "tests/calibration/board_views_support.hpp"

namespace surroundd::calibration::testing {
namespace {

struct Case {
  std::string name;
  std::string rig;
  processing::CalibrationBoard board;
  int views;
  int margin;  // > 0: boards cut off at the image edge
  std::uint64_t seed;
  Hardship hardship{};
};

class AnyBoard : public ::testing::TestWithParam<Case> {};

TEST_P(AnyBoard, GivesTheTrueLens) {
  const auto& c = GetParam();
  const auto truth = presetCameras(c.rig).front().intrinsics;
  const auto images = anyBoardViews(truth, c.board, c.views, c.seed, c.margin, c.hardship);
  std::vector<processing::BoardView> views;
  int cutOff = 0;
  double widestEdgesPx = 0;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const cv::Mat gray = toGray(images[i]);
    auto found = processing::findBoard(gray, c.board);
    if (found.outcome != processing::BoardSearch::Outcome::kFound) continue;
    if (static_cast<int>(found.corners.size()) < c.board.innerCorners().area()) ++cutOff;
    views.push_back({fmt::format("view{}", i), std::move(found.corners), std::move(found.grid)});
    // Sharp renders well inside the blur limit; blurred ones still inside it.
    const double edgesPx = processing::edgeWidthPx(gray, views.back());
    EXPECT_LT(edgesPx,
              c.hardship.blurSigmaPx > 0 ? processing::CalibrationLimits{}.maxEdgeWidthPx : 3.0)
        << views.back().name;
    widestEdgesPx = std::max(widestEdgesPx, edgesPx);
  }
  EXPECT_GE(views.size(), images.size() * 3 / 4);
  if (c.margin > 0) {
    EXPECT_GE(cutOff, 3) << "views cut off at the edge";
  }
  EXPECT_TRUE(processing::findDuplicateViews(views).empty());
  const processing::CalibrationLimits limits;
  const auto robust =
      processing::calibrateLeavingOutBadViews(truth.model, truth.imageSize, views, limits);
  const auto& lens = robust.result.intrinsics;
  const auto coverage = processing::coverageOf(views, truth.imageSize, {});
  const auto verdict = processing::judgeCalibration(robust.result, coverage.coveredShare, limits);
  EXPECT_TRUE(verdict.passed) << fmt::format("{}", fmt::join(verdict.failures, "; "));
  const double fxError = 100 * (lens.fx / truth.fx - 1), fyError = 100 * (lens.fy / truth.fy - 1);
  EXPECT_LT(std::abs(fxError), 0.5);
  EXPECT_LT(std::abs(fyError), 0.5);
  EXPECT_NEAR(lens.cx, truth.cx, 1.0);
  EXPECT_NEAR(lens.cy, truth.cy, 1.0);
  // The stated uncertainty is of the size of the error, not orders away from it.
  EXPECT_GT(robust.result.uncertainty.fx, 0);
  EXPECT_LT(robust.result.uncertainty.fx, 0.01 * truth.fx);
  const auto figures = fmt::format(
      "{}: {} of {} views used ({} found, {} cut off; edges up to {:.1f} px wide), fx {:+.3f} % "
      "fy {:+.3f} % (sd {:.2f} px), cx {:+.2f} cy {:+.2f} px, RMS {:.3f} px, coverage {:.0f} %",
      c.name, robust.result.views.size(), images.size(), views.size(), cutOff, widestEdgesPx,
      fxError, fyError, robust.result.uncertainty.fx, lens.cx - truth.cx, lens.cy - truth.cy,
      robust.result.rmsPx, 100 * coverage.coveredShare);
  std::cout << figures << "\n";
  RecordProperty("figures", figures);
}

INSTANTIATE_TEST_SUITE_P(
    Boards, AnyBoard,
    ::testing::Values(
        Case{"chess7x7_pinhole", "paper.yaml", chessboard(7, 7), 10, 0, 11},
        Case{"chess8x8_fisheye", "fisheye.yaml", chessboard(8, 8), 12, 0, 12},
        Case{"chess9x6_pinhole_partial", "paper.yaml", chessboard(9, 6), 12, 200, 13},
        Case{"chess9x6_fisheye_partial", "fisheye.yaml", chessboard(9, 6), 14, 150, 14},
        Case{"charuco8x6_pinhole", "paper.yaml", charucoBoard(8, 6), 10, 0, 15},
        Case{"charuco8x6_fisheye_partial", "fisheye.yaml", charucoBoard(8, 6), 14, 70, 16},
        // The harder fisheye pictures: blurred (edges up to 2.8 px wide), four times the
        // noise, the edge of the field at half brightness, boards cut off at the image edge.
        Case{"chess9x6_fisheye_hard", "fisheye.yaml", chessboard(9, 6), 14, 150, 17,
             Hardship{1.0, 6.0, 0.7}},
        Case{"charuco8x6_fisheye_hard", "fisheye.yaml", charucoBoard(8, 6), 14, 70, 18,
             Hardship{1.0, 6.0, 0.7}}),
    [](const auto& test) { return test.param.name; });

}  // namespace
}  // namespace surroundd::calibration::testing
