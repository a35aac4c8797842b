#include "processing/calibration/agreed_corrections.hpp"

#include <cmath>

namespace surroundd::processing {

std::vector<std::size_t> AgreedCorrections::add(const MountRefinementResult& solution,
                                                const Rig& rig) {
  before_.resize(rig.cameras.size());
  std::vector<std::size_t> agreed;
  for (std::size_t c = 0; c < rig.cameras.size() && c < solution.cameras.size(); ++c) {
    std::optional<MountAngles> now;
    if (solution.verdict(c) == CorrectionVerdict::kOffered) {
      const Pose& pose = rig.cameras[c].pose;
      now = mountAngleChange(pose, solution.cameras[c].applied(pose));
    }
    const auto& before = before_[c];
    if (now && before && std::abs(now->yawDeg - before->yawDeg) <= kAgreeDeg &&
        std::abs(now->pitchDeg - before->pitchDeg) <= kAgreeDeg &&
        std::abs(now->rollDeg - before->rollDeg) <= kAgreeDeg) {
      agreed.push_back(c);
    }
    before_[c] = now;
  }
  return agreed;
}

}  // namespace surroundd::processing
