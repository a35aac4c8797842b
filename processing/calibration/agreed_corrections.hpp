#pragma once
// Which cameras' mount corrections to make (calibration_watch.correct: apply): those that two
// solutions in a row offer alike, each angle within kAgreeDeg. One solution can be a passing car's
// or a stretch of ground that fooled the fit; two in a row, made from sets that differ, rarely
// are.

#include <cstddef>
#include <optional>
#include <vector>

#include "processing/calibration/mount_refinement.hpp"
#include "processing/rig.hpp"

namespace surroundd::processing {

class AgreedCorrections {
 public:
  static constexpr double kAgreeDeg = 0.2;

  // The cameras of `rig` (the mounts `solution` corrects) whose correction in `solution`
  // (CorrectionVerdict::kOffered) the solution given before offered alike.
  std::vector<std::size_t> add(const MountRefinementResult& solution, const Rig& rig);
  // Solutions from here on start again (the mounts they correct have changed).
  void clear() { before_.clear(); }

 private:
  std::vector<std::optional<MountAngles>> before_;  // per camera: the last solution's offer
};

}  // namespace surroundd::processing
