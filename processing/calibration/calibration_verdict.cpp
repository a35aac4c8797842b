#include "processing/calibration/calibration_verdict.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "processing/calibration/view_acceptance.hpp"
#include "processing/lens/camera_model.hpp"

namespace surroundd::processing {
namespace {

constexpr double kToDeg = 180 / std::numbers::pi;

// The views' edge width as a whole: their median.
double typicalEdgeWidthPx(const IntrinsicCalibration& result) {
  std::vector<double> widths;
  widths.reserve(result.views.size());
  for (const auto& view : result.views) widths.push_back(view.edgeWidthPx);
  return median(std::move(widths));
}

// "the limit of 1 px", or where the pictures set it, "the limit of 1.75 px (0.35 of the views'
// 5.0 px wide edges)".
std::string limitText(double limitPx, double floorPx, double perEdge, double edgeWidthPx) {
  if (limitPx <= floorPx) return fmt::format("the limit of {:.3g} px", limitPx);
  return fmt::format("the limit of {:.3g} px ({:g} of the views' {:.1f} px wide edges)", limitPx,
                     perEdge, edgeWidthPx);
}

std::vector<const ViewResiduals*> worstFirst(const IntrinsicCalibration& result) {
  std::vector<const ViewResiduals*> views;
  for (const auto& view : result.views) views.push_back(&view);
  std::stable_sort(views.begin(), views.end(),
                   [](const auto* a, const auto* b) { return a->rmsPx > b->rmsPx; });
  return views;
}

}  // namespace

Verdict judgeCalibration(const IntrinsicCalibration& result, double coverage,
                         const CalibrationLimits& limits) {
  Verdict verdict;
  const auto fail = [&](std::string sentence) {
    verdict.passed = false;
    verdict.failures.push_back(std::move(sentence));
  };
  const auto& lens = result.intrinsics;
  const double width = lens.imageSize.width;
  if (static_cast<int>(result.views.size()) < limits.minViews) {
    fail(fmt::format("{} views were used, at least {} are needed", result.views.size(),
                     limits.minViews));
  }
  const double edgeWidth = typicalEdgeWidthPx(result);
  if (const double limit = limits.rmsLimitPx(edgeWidth);
      !std::isfinite(result.rmsPx) || result.rmsPx > limit) {
    fail(fmt::format("RMS {:.3g} px is above {}", result.rmsPx,
                     limitText(limit, limits.maxRmsPx, limits.rmsPerEdgeWidth, edgeWidth)));
  }
  const auto& sd = result.uncertainty;
  if (const double focalSdPercent = 100 * std::max(sd.fx / lens.fx, sd.fy / lens.fy);
      !(focalSdPercent <= limits.maxFocalSdPercent)) {
    fail(fmt::format(
        "the focal length is not pinned down: +-{:.2f} % (one standard deviation), at most {:g} % "
        "(more views, tilted other ways)",
        focalSdPercent, limits.maxFocalSdPercent));
  }
  if (const double ppSd = std::max(sd.cx, sd.cy); !(ppSd <= limits.maxPrincipalSdPx)) {
    fail(fmt::format(
        "the principal point is not pinned down: +-{:.2f} px (one standard deviation), at most "
        "{:g} px (more views near the edges)",
        ppSd, limits.maxPrincipalSdPx));
  }
  for (const double f : {lens.fx, lens.fy}) {
    if (!std::isfinite(f) || f < limits.minFocalPerWidth * width ||
        f > limits.maxFocalPerWidth * width) {
      fail(
          fmt::format("the focal length {:.4g} px is not that of a lens on a {} px wide image "
                      "({:g} to {:g} px)",
                      f, lens.imageSize.width, limits.minFocalPerWidth * width,
                      limits.maxFocalPerWidth * width));
      break;
    }
  }
  const double fromGuess = lens.fx / result.startingFocalPx;
  if (std::abs(fromGuess - 1) < 1e-6) {
    fail(
        fmt::format("the focal length {:.4g} px is still the solver's starting guess: it did "
                    "not converge",
                    lens.fx));
  } else if (!(fromGuess < limits.maxFocalFromGuess && fromGuess > 1 / limits.maxFocalFromGuess)) {
    fail(
        fmt::format("the focal length {:.4g} px ran {:.3g} times away from the starting guess "
                    "{:.4g} px (limit {:g}): the solve did not converge to a lens",
                    lens.fx, fromGuess, result.startingFocalPx, limits.maxFocalFromGuess));
  }
  const double aspect = lens.fx / lens.fy;
  if (!(aspect < limits.maxAspect && aspect > 1 / limits.maxAspect)) {
    fail(fmt::format("fx / fy = {:.3g}, beyond {:g} either way: pixels are not that oblong", aspect,
                     limits.maxAspect));
  }
  if (const auto cut = CameraModel(lens).fieldCut();
      cut && cut->atRad < result.widestCornerAngleRad) {
    fail(
        fmt::format("the distortion stops increasing at {:.1f} deg off the axis, inside the "
                    "{:.1f} deg the corners reached: two directions would share a pixel",
                    cut->atRad * kToDeg, result.widestCornerAngleRad * kToDeg));
  }
  if (coverage < limits.minCoverage) {
    fail(
        fmt::format("the corners cover {:.0f} % of the image, at least {:.0f} % is needed "
                    "(see the coverage picture; move the board into the empty parts)",
                    100 * coverage, 100 * limits.minCoverage));
  }
  for (const auto* view : worstFirst(result)) {
    if (!(view->rmsPx <= limits.viewRmsLimitPx(view->edgeWidthPx))) {
      verdict.viewsToDrop.push_back(view->name);
    }
  }
  // A failed solve with no view bad by itself: dropping views only weakens it (advice to drop
  // the worst few would go round until too few were left).
  if (!verdict.passed && verdict.viewsToDrop.empty() && !result.views.empty()) {
    const auto* worst = worstFirst(result).front();
    verdict.failures.push_back(fmt::format(
        "no view is to blame (the worst, {}, is {:.3g} px, within its {:.3g} px): add pictures "
        "rather than drop them, with the board tilted 30 to 45 degrees different ways and in the "
        "parts of the picture that have no corners yet",
        worst->name, worst->rmsPx, limits.viewRmsLimitPx(worst->edgeWidthPx)));
  }
  return verdict;
}

RobustCalibration calibrateLeavingOutBadViews(LensModel model, cv::Size imageSize,
                                              std::vector<BoardView> views,
                                              const CalibrationLimits& limits) {
  RobustCalibration robust;
  robust.result = calibrateIntrinsics(model, imageSize, views);
  while (static_cast<int>(views.size()) > limits.minViews) {
    const auto worst = std::max_element(
        robust.result.views.begin(), robust.result.views.end(),
        [](const auto& a, const auto& b) { return a.rmsPx < b.rmsPx || std::isnan(b.rmsPx); });
    const double limit = limits.viewRmsLimitPx(worst->edgeWidthPx);
    if (worst->rmsPx <= limit) break;
    robust.leftOut.push_back(
        fmt::format("{}: RMS {:.3g} px, above its {:.3g} px", worst->name, worst->rmsPx, limit));
    views.erase(views.begin() + (worst - robust.result.views.begin()));
    robust.result = calibrateIntrinsics(model, imageSize, views);
  }
  return robust;
}

std::optional<std::string> blurProblem(const BoardView& view, const CalibrationLimits& limits) {
  const double square = squareSizePx(view);
  const double limit = limits.edgeWidthLimitPx(square);
  if (view.edgeWidthPx <= limit) return std::nullopt;
  return fmt::format("too blurred: its edges are {:.1f} px wide, the limit is {:.3g} px ({})",
                     view.edgeWidthPx, limit,
                     limits.edgeWidthPerSquare > 0
                         ? fmt::format("{:g} of its board's {:.0f} px squares, at least {:g} px; "
                                       "--max-edge-width-px",
                                       limits.edgeWidthPerSquare, square, limits.maxEdgeWidthPx)
                         : std::string("--max-edge-width-px"));
}

}  // namespace surroundd::processing
