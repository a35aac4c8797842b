#pragma once
// The verdict of a mat calibration as surround-calibrate prints it: a table per camera (boards
// found, corners, reprojection RMS, change from the rig's mount, what failed), each board's RMS,
// and the seam error on the ground of every board two cameras share.

#include <ostream>

#include "processing/calibration/mat_calibration.hpp"

namespace surroundd::calibrate {

void printMatReport(const processing::MatLayout& mat, const processing::MatCalibration& result,
                    std::ostream& log);

}  // namespace surroundd::calibrate
