#pragma once
// surround-calibrate mask: each camera's body mask (daemon::bodyMaskOf, exactly what surroundd
// leaves out of the panorama) drawn on the camera's first picture, so that a user can check it,
// and the mask alone as a picture to edit and give back as `body_mask: {file: ..., mode: replace}`.

#include <ostream>

#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {

// Writes <camera>-mask-overlay.png and <camera>-body.png into options.out for every camera (or
// options.camera), a line per camera to `log`, then the YAML that uses the edited masks. Throws
// UsageError for an unknown camera, a frame that cannot be read or a mask picture that does not
// fit; ConfigError (from daemon::loadConfig) for a bad config.
void runMask(const MaskOptions& options, std::ostream& log);

}  // namespace surroundd::calibrate
