// The verdict's limits scale with the pictures (issue 47): the RMS with the views' edge width, the
// blur limit with the board's squares in the picture; a pixel limit the user gives is exact; the
// solve's uncertainty gates every command's lens; and when no view is to blame the advice is to
// add pictures, never to drop more.

#include "processing/calibration/calibration_verdict.hpp"

#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace surroundd::calibration::testing {
namespace {

using ::testing::HasSubstr;
using ::testing::IsEmpty;

// A solve of six views that fits as well as pictures with `edgeWidthPx` wide edges allow: its
// lens a 1920x1080 camera's, pinned down to +-0.1 % and +-0.5 px.
processing::IntrinsicCalibration solveOf(double rmsPx, double edgeWidthPx) {
  processing::IntrinsicCalibration result;
  auto& lens = result.intrinsics;
  lens.imageSize = {1920, 1080};
  lens.fx = lens.fy = 800;
  lens.cx = 960;
  lens.cy = 540;
  result.uncertainty = {0.8, 0.8, 0.5, 0.5, {}};
  result.rmsPx = rmsPx;
  result.startingFocalPx = 700;
  for (int v = 0; v < 6; ++v) {
    processing::ViewResiduals view;
    view.name = "view_0" + std::to_string(v);
    view.rmsPx = rmsPx;
    view.edgeWidthPx = edgeWidthPx;
    result.views.push_back(view);
  }
  return result;
}

TEST(CalibrationVerdict, TheRmsLimitFollowsTheViewsEdgeWidthUnlessGiven) {
  const processing::CalibrationLimits limits;
  EXPECT_TRUE(processing::judgeCalibration(solveOf(1.6, 5.0), 0.5, limits).passed);
  const auto sharp = processing::judgeCalibration(solveOf(1.6, 1.2), 0.5, limits);
  EXPECT_FALSE(sharp.passed);
  EXPECT_THAT(sharp.failures[0], HasSubstr("RMS 1.6 px is above the limit of 1 px"));
  const auto blurred = processing::judgeCalibration(solveOf(2.0, 5.0), 0.5, limits);
  EXPECT_FALSE(blurred.passed);
  EXPECT_THAT(blurred.failures[0],
              HasSubstr("above the limit of 1.75 px (0.35 of the views' 5.0 px wide edges)"));
  processing::CalibrationLimits given;
  given.rmsPerEdgeWidth = 0;  // --max-rms-px given
  EXPECT_FALSE(processing::judgeCalibration(solveOf(1.6, 5.0), 0.5, given).passed);
}

TEST(CalibrationVerdict, ALensNotPinnedDownFailsAndNoViewIsToBlame) {
  auto loose = solveOf(0.3, 1.5);
  loose.uncertainty.fx = 12;  // 1.5 %
  loose.uncertainty.cx = 3;
  const auto verdict = processing::judgeCalibration(loose, 0.5, {});
  EXPECT_FALSE(verdict.passed);
  EXPECT_THAT(verdict.failures[0], HasSubstr("the focal length is not pinned down: +-1.50 %"));
  EXPECT_THAT(verdict.failures[1], HasSubstr("the principal point is not pinned down: +-3.00 px"));
  // Every view fits: dropping one would only weaken the set.
  EXPECT_THAT(verdict.viewsToDrop, IsEmpty());
  EXPECT_THAT(verdict.failures.back(), HasSubstr("no view is to blame"));
  EXPECT_THAT(verdict.failures.back(), HasSubstr("add pictures rather than drop them"));
}

TEST(CalibrationVerdict, TheBlurLimitFollowsTheBoardsSquares) {
  // A 7x7 grid of 60 px squares.
  processing::BoardView view{"large", {}, {}, 5.0};
  for (int row = 0; row < 7; ++row) {
    for (int column = 0; column < 7; ++column) {
      view.corners.emplace_back(100 + 60 * column, 100 + 60 * row);
      view.grid.emplace_back(column, row);
    }
  }
  const processing::CalibrationLimits limits;
  EXPECT_EQ(processing::blurProblem(view, limits), std::nullopt);  // limit 6 px
  view.edgeWidthPx = 6.5;
  const auto blurred = processing::blurProblem(view, limits);
  ASSERT_TRUE(blurred.has_value());
  EXPECT_THAT(*blurred, HasSubstr("its edges are 6.5 px wide, the limit is 6 px (0.1 of its "
                                  "board's 60 px squares, at least 4 px"));
  processing::CalibrationLimits given;
  given.edgeWidthPerSquare = 0;  // --max-edge-width-px given
  view.edgeWidthPx = 5.0;
  ASSERT_TRUE(processing::blurProblem(view, given).has_value());
  EXPECT_THAT(*processing::blurProblem(view, given),
              HasSubstr("the limit is 4 px (--max-edge-width-px)"));
}

}  // namespace
}  // namespace surroundd::calibration::testing
