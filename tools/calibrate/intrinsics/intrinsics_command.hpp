#pragma once
// surround-calibrate intrinsics: checkerboard images in, the camera's lens: block out.

#include <ostream>

#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {

// Prints a per-image report to `log`. Throws UsageError (bad input: the folder, an image),
// processing::CalibrationError (too little in the images) or std::runtime_error (cannot write).
void runIntrinsics(const IntrinsicsOptions& options, std::ostream& log);

}  // namespace surroundd::calibrate
