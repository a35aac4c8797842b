#pragma once
// The lens of an imported camera from the parts its files gave (foreign_calibration.hpp), in the
// project's lens models (processing/camera_model.hpp).

#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "tools/calibrate/foreign_calibration.hpp"
#include "tools/calibrate/import_options.hpp"

namespace surroundd::calibrate {

// `pictureSize`: the camera's still picture, when there is one (the size of last resort).
// Throws UsageError naming the camera, file and key for what is missing or does not fit.
processing::Intrinsics importedLens(const std::string& camera, const ForeignCalibration& found,
                                    const ImportOptions& options,
                                    std::optional<cv::Size> pictureSize);

// A fisheye or ocam lens's full field when none is given: as far as its image reaches (the
// farthest image corner), no further than where its polynomial stops increasing. Degrees.
double fieldToImageCorner(const processing::Intrinsics& lens);

}  // namespace surroundd::calibrate
