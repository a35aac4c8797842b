#pragma once
// Where a seam's two cameras both see the ground, as patches to compare (seam_misalignment.hpp's
// probe): square patches laid where the overlap (past the body, within 12 m of both cameras) is
// widest around a point, nearest the two cameras first, apart by half a patch at least, 24 at
// most; each as large as the overlap allows up to 1.6 m, and sampled as finely as the coarser
// camera sees that ground (no finer than 1 cm). Made once per set of mounts (tens of
// milliseconds a seam).
//
// Errors: none thrown; a seam whose cameras share no ground has no patch.

#include <vector>

#include "processing/calibration/seam_misalignment.hpp"
#include "processing/rig.hpp"

namespace surroundd::processing {

std::vector<SeamMisalignmentProbe> overlapPatches(const Rig& rig, const SeamLine& seam);

}  // namespace surroundd::processing
