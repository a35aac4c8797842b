#pragma once
// A body mask drawn on a camera's picture, for a user to check it (surround-calibrate mask).

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace surroundd::calibrate {

// `picture` (8-bit BGR) with the pixels of `mask` (CV_8U, non-zero = body) blended half with red,
// its outline (holes too) drawn 2 px wide in yellow, and `label`'s lines in white on black in the
// corner where they hide the least of the mask.
cv::Mat maskOverlay(const cv::Mat& picture, const cv::Mat& mask,
                    const std::vector<std::string>& label);

}  // namespace surroundd::calibrate
