#pragma once
// surround-calibrate refine: the cameras' mounts corrected from the ground their neighbours also
// see (processing/calibration/mount_refinement.hpp), in a recording of a drive or in one still
// picture per camera, with the pictures of the ground from above before and after.

#include <ostream>

#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {

// Prints each camera's correction (mount angles and height, with their uncertainty; the camera
// held; whether it is conclusive) and each seam's misalignment before and after; writes
// options.out/mounts.yaml (the refined mount: blocks, the corrections worth applying only) and
// top-before.png / top-after.png; with options.updateRig, the mounts into the rig file (the file
// before kept beside it as FILE.before-refine). Throws UsageError for missing or unreadable
// pictures and for too little ground that two cameras share; ConfigError for a bad config or rig.
void runRefine(const RefineOptions& options, std::ostream& log);

}  // namespace surroundd::calibrate
