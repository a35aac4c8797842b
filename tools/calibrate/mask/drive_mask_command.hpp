#pragma once
// surround-calibrate mask --from: each camera's body found in a recording of a drive
// (processing/calibration/body_from_motion.hpp), written as a picture, drawn on the drive's last
// picture, and printed as polygons ready to paste into the rig as the camera's body_mask:.

#include <ostream>

#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {

// Writes <camera>-found-body.png and <camera>-found-overlay.png into options.out for every camera
// (or options.camera) of the recording options.from, a line per camera to `log`, then the YAML.
// Throws UsageError naming the recording and the camera for one that cannot be read, is live, has
// too few pictures or did not move; ConfigError for a rig file that cannot be read.
void runDriveMask(const MaskOptions& options, std::ostream& log);

}  // namespace surroundd::calibrate
