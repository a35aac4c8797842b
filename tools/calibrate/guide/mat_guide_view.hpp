#pragma once
// The picture the guided mat calibration's page streams: each camera's picture with the boards
// it found (green: the camera passed, amber: it did not), and beside them the ground stitched
// through the solved mounts with the mat's boards where the layout puts them and each seam's
// error in centimetres (green within the limit, red over it).

#include <opencv2/core.hpp>

#include "tools/calibrate/guide/mat_guide_session.hpp"

namespace surroundd::calibrate {

// 8-bit BGR, always kMatGuideFrameSize (a stream keeps one size).
inline const cv::Size kMatGuideFrameSize{1280, 720};
cv::Mat matGuideFrame(const MatGuideSession& session);

}  // namespace surroundd::calibrate
