#pragma once
// Whether a lens solve can be trusted, against limits a user can set, and the solve that leaves
// out views whose error is too large by itself (an absolute limit: when every view is bad, every
// view is named, which a comparison with the median never does).

#include <algorithm>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "processing/calibration/calibration_board.hpp"
#include "processing/calibration/intrinsic_calibration.hpp"

namespace surroundd::processing {

// The limits on pixels scale with what the pictures show: blur and compression move a corner by a
// share of its edges' width, and a board seen large may be blurred more than a small one before
// its corners move. So a sharp small board is held to the pixel limits, and a large board in a
// 1920-pixel JPEG with 5-pixel edges (an automotive camera's) to what its pictures allow; the
// solve's own uncertainty then says whether the lens is pinned down.
struct CalibrationLimits {
  double maxRmsPx = 1.0;        // over every corner of every view used
  double maxViewRmsPx = 2.0;    // a view above it is left out of the solve (and named)
  double maxEdgeWidthPx = 4.0;  // a picture whose edges are wider is too blurred to use
  // The RMS limits are at least these shares of the views' median edge width, and of a view's.
  double rmsPerEdgeWidth = 0.35;
  double viewRmsPerEdgeWidth = 0.7;
  // The edge width limit is at least this share of the board's squares in that picture.
  double edgeWidthPerSquare = 0.1;
  // One standard deviation of the solve (its covariance): focal lengths, share of themselves;
  // principal point, pixels.
  double maxFocalSdPercent = 0.5;
  double maxPrincipalSdPx = 2.0;
  double minCoverage = 0.35;  // share of the lens's image cells with corners (CoverageMap)
  int minViews = kMinimumBoardViews;
  // The focal length against the image width (a 2-degree telephoto to a 240-degree fisheye) and
  // against the solver's starting guess: a solve that never left its guess, or ran far from it,
  // did not converge to a lens.
  double minFocalPerWidth = 0.08;
  double maxFocalPerWidth = 30;
  double maxFocalFromGuess = 4;  // factor either way
  double maxAspect = 1.25;       // fx / fy, either way

  double edgeWidthLimitPx(double squarePx) const {
    return std::max(maxEdgeWidthPx, edgeWidthPerSquare * squarePx);
  }
  double rmsLimitPx(double edgeWidthPx) const {
    return std::max(maxRmsPx, rmsPerEdgeWidth * edgeWidthPx);
  }
  double viewRmsLimitPx(double edgeWidthPx) const {
    return std::max(maxViewRmsPx, viewRmsPerEdgeWidth * edgeWidthPx);
  }
};

// Whether a found view is sharp enough to solve with: its edges within edgeWidthLimitPx of its
// squares; else why not, one sentence naming the limit's option.
std::optional<std::string> blurProblem(const BoardView& view, const CalibrationLimits& limits);

struct Verdict {
  bool passed = true;
  std::vector<std::string> failures;     // one sentence each
  std::vector<std::string> viewsToDrop;  // names, worst first
};

// Judges a solve. `coverage`: CoverageMap::coveredShare of the views used.
Verdict judgeCalibration(const IntrinsicCalibration& result, double coverage,
                         const CalibrationLimits& limits);

struct RobustCalibration {
  IntrinsicCalibration result;
  std::vector<std::string> leftOut;  // "name: RMS 3.41 px" for each view the solve dropped
};

// Solves, then while the worst view's RMS is above its limit (viewRmsLimitPx) and more than
// limits.minViews views remain, leaves that view out and solves again.
RobustCalibration calibrateLeavingOutBadViews(LensModel model, cv::Size imageSize,
                                              std::vector<BoardView> views,
                                              const CalibrationLimits& limits);

}  // namespace surroundd::processing
