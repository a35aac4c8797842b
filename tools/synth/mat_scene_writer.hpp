#pragma once
// surround-synth --calibration-mat: what a calibration session on a production line gives, with
// the truth. Writes into --out one picture per camera of a calibration mat laid around the rig
// (NAME.png, rendered with TargetRenderer through the camera's lens and photometrics), the mat's
// layout (mat.yaml), the rig that rendered them (rig.yaml, the exact poses) and the same rig with
// each mount a few centimetres and degrees off (nominal-rig.yaml, where a calibration starts).

#include <ostream>

#include "tools/synth/synth_options.hpp"

namespace surroundd::synth {

// Throws UsageError when --out exists without --force, or no place fits a board.
void writeMatScene(const SynthOptions& options, std::ostream& log);

}  // namespace surroundd::synth
