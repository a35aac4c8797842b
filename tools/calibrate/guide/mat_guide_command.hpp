#pragma once
// surround-calibrate guide --mat: every camera the calibration mat names read (live devices, or
// still pictures) into a MatGuideSession, its state and the stitched top view served on a page
// until Ctrl-C; every camera's mount is written into the rig when the session passes.

#include <ostream>

#include "tools/calibrate/guide/mat_guide_options.hpp"

namespace surroundd::calibrate {

// Prints the page's address, each solve's table and the verdict to `log`. Throws UsageError when
// a camera has no source or cannot be opened, std::runtime_error when the page cannot be served,
// and processing::CalibrationError when it stops before the mounts passed and were written.
void runMatGuide(const MatGuideOptions& options, std::ostream& log);

}  // namespace surroundd::calibrate
