#pragma once
// surround-calibrate extrinsics: one camera's image of markers at known places in, its mount:
// block out.

#include <ostream>

#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {

// Prints what was found and the pose to `log`. Throws UsageError or daemon::ConfigError (bad
// input), processing::CalibrationError (too little found) or std::runtime_error (cannot write).
void runExtrinsics(const ExtrinsicsOptions& options, std::ostream& log);

}  // namespace surroundd::calibrate
