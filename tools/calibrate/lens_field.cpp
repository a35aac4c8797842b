#include "tools/calibrate/lens_field.hpp"

#include <algorithm>
#include <numbers>

namespace surroundd::calibrate {

processing::ImageCircle lensCircle(processing::LensModel model, const cv::Mat& brightest) {
  if (!processing::isWideAngle(model)) {
    return {cv::Mat(brightest.size(), CV_8U, cv::Scalar(255)), false};
  }
  return processing::findImageCircle(brightest);
}

processing::FieldOfView limitField(processing::Intrinsics& lens,
                                   const processing::ImageCircle& circle,
                                   std::span<const processing::BoardView> views,
                                   std::optional<double> givenDeg) {
  // A pinhole lens's field is its picture's (what it writes has none): only a wide lens is
  // extrapolated far past its corners.
  const bool wide = processing::isWideAngle(lens.model);
  auto field = processing::fieldOfViewOf(
      lens, circle,
      wide ? std::optional(processing::widestCornerAngleRad(lens, views)) : std::nullopt);
  if (lens.model == processing::LensModel::kFisheye) {
    if (givenDeg) field = {*givenDeg, false, "given by --field-of-view-deg"};
    lens.maxFieldAngleRad = std::min(lens.maxFieldAngleRad, field.fullDeg * std::numbers::pi / 360);
  }
  return field;
}

}  // namespace surroundd::calibrate
