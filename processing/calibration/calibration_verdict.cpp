#include "processing/calibration/calibration_verdict.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "processing/camera_model.hpp"

namespace surroundd::processing {
namespace {

constexpr double kToDeg = 180 / std::numbers::pi;

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
  if (!std::isfinite(result.rmsPx) || result.rmsPx > limits.maxRmsPx) {
    fail(fmt::format("RMS {:.3g} px is above the limit of {:g} px", result.rmsPx, limits.maxRmsPx));
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
    if (!(view->rmsPx <= limits.maxViewRmsPx)) verdict.viewsToDrop.push_back(view->name);
  }
  // A failed solve with no single bad view: the worst few are where to look first.
  if (!verdict.passed && verdict.viewsToDrop.empty() && !result.views.empty()) {
    const auto worst = worstFirst(result);
    for (std::size_t i = 0; i < std::min<std::size_t>(3, worst.size()); ++i) {
      verdict.viewsToDrop.push_back(worst[i]->name);
    }
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
    if (worst->rmsPx <= limits.maxViewRmsPx) break;
    robust.leftOut.push_back(fmt::format("{}: RMS {:.3g} px", worst->name, worst->rmsPx));
    views.erase(views.begin() + (worst - robust.result.views.begin()));
    robust.result = calibrateIntrinsics(model, imageSize, views);
  }
  return robust;
}

}  // namespace surroundd::processing
