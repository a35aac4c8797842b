#pragma once
// How much of the picture a solved lens covers, shared by surround-calibrate intrinsics and
// guide: the image circle from the pictures and the field of view that follows from it.

#include <optional>
#include <span>

#include <opencv2/core.hpp>

#include "processing/calibration/calibration_coverage.hpp"
#include "processing/rig.hpp"

namespace surroundd::calibrate {

// The lens's image circle from the brightest value of each pixel over the pictures (CV_8U). A
// pinhole lens's image fills the sensor: dark corners there are vignetting or the scene, so every
// pixel counts.
processing::ImageCircle lensCircle(processing::LensModel model, const cv::Mat& brightest);

// The field of view of `lens` solved from `views` (see processing::fieldOfViewOf: within the image
// circle and a few degrees past the widest corner), or `givenDeg` for a fisheye when the user gave
// it; a fisheye's maxFieldAngleRad is limited to it (within the polynomial's monotonic range,
// which the solve left in the field).
processing::FieldOfView limitField(processing::Intrinsics& lens,
                                   const processing::ImageCircle& circle,
                                   std::span<const processing::BoardView> views,
                                   std::optional<double> givenDeg);

}  // namespace surroundd::calibrate
