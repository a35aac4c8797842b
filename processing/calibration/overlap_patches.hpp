#pragma once
// Where a seam's two cameras both see the ground, as patches to compare (seam_misalignment.hpp's
// probe): square patches laid where the overlap (past the body, within 12 m of both cameras) is
// widest around a point, large ones near the two cameras first, apart by a quarter of their
// sides at least, 24 at most of each size; each as large as the overlap allows up to a size, and
// sampled as finely as the coarser camera sees that ground. Made once per set of mounts (tens of
// milliseconds a seam).
//
// Errors: none thrown; a seam whose cameras share no ground has no patch.

#include <span>
#include <vector>

#include "processing/calibration/seam_misalignment.hpp"
#include "processing/rig.hpp"

namespace surroundd::processing {

struct PatchSizes {
  double largestM = 1.6;
  double smallestM = 0.6;
  double finestM = 0.01;  // a pixel of the patch, at least
};
// Fine patches: precise to a centimetre, they lose a shift past a quarter of their side (40 cm).
inline constexpr PatchSizes kFinePatches{1.6, 0.6, 0.01};
// Coarse ones: a few centimetres, but shifts of up to 80 cm (a mount a few degrees off).
inline constexpr PatchSizes kCoarsePatches{3.2, 1.2, 0.025};

// Each of `sizeRanges` laid in turn over the one overlap (24 patches at most of each).
std::vector<SeamMisalignmentProbe> overlapPatches(const Rig& rig, const SeamLine& seam,
                                                  std::span<const PatchSizes> sizeRanges);

}  // namespace surroundd::processing
