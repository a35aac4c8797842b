#pragma once
// surround-bench mounts: the calibration watch's mount refinement (processing/calibration/
// mount_refinement.hpp, at the daemon's cadence: a set compared every second of stream time,
// solved every ten) replayed over generated drives, against their truth: where a camera was
// knocked (surround-synth --turn), how long after the turn a correction worth applying came, how
// far the corrected mount is from the mount after the turn, the seams before and after; where no
// camera was, every correction worth applying is a false alarm. And what a compared set costs.

#include <filesystem>
#include <vector>

namespace surroundd::bench {

// Prints a report per recording; returns 0, or 1 when one cannot be read.
int runMountBenchmark(const std::vector<std::filesystem::path>& recordings);

}  // namespace surroundd::bench
