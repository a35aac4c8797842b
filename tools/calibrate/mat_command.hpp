#pragma once
// surround-calibrate extrinsics --mat: every camera a calibration mat names, from one picture
// each; writes the mount: blocks (and updates the rig) only when every camera and seam passed.

#include <ostream>

#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {

void runMatExtrinsics(const ExtrinsicsOptions& options, std::ostream& log);

}  // namespace surroundd::calibrate
