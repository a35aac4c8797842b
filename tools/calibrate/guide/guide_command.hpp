#pragma once
// surround-calibrate guide: one camera read live (or a recording replayed at its own pace) into
// a GuideSession, its state served on a page (guide_page.hpp) until Ctrl-C; the lens block is
// written when the session passes.

#include <ostream>

#include "tools/calibrate/guide/guide_options.hpp"

namespace surroundd::calibrate {

// Prints the page's address, each view kept and the verdicts to `log`. Throws UsageError when the
// camera cannot be opened (naming it), std::runtime_error when the page cannot be served, and
// processing::CalibrationError when it stops (Ctrl-C, or the recording ended) before a pass.
void runGuide(const GuideOptions& options, std::ostream& log);

}  // namespace surroundd::calibrate
