#pragma once
// The lens of an imported camera from the parts its files gave (foreign_calibration.hpp), in the
// project's lens models (processing/lens/camera_model.hpp).

#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "tools/calibrate/import/foreign_calibration.hpp"
#include "tools/calibrate/import/import_options.hpp"

namespace surroundd::calibrate {

// `picture`: the camera's still picture, or empty. It gives the image size when nothing else
// does, and a fisheye or ocam lens's default field: as far as the picture is lit (the lens's
// image circle), no further than where the polynomial stops increasing.
// Throws UsageError naming the camera, file and key for what is missing or does not fit.
processing::Intrinsics importedLens(const std::string& camera, const ForeignCalibration& found,
                                    const ImportOptions& options, const cv::Mat& picture);

// A fisheye or ocam lens's full field when neither it nor a picture is given: as far as its image
// reaches (the farthest image corner), no further than where its polynomial stops increasing.
// Degrees.
double fieldToImageCorner(const processing::Intrinsics& lens);

}  // namespace surroundd::calibrate
