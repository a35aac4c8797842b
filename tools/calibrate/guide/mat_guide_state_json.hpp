#pragma once
// The guided mat calibration's state as the JSON its page reads (/state.json), so that the page
// only draws:
//
//   {"phase": "waiting" | "failed" | "passed" | "ended", "solves": N, "seamLimitCm": C,
//    "cameras": [{"name", "frames", "boardsFound", "boardsExpected", "corners",
//                 "rmsPx" | null, "movedCm" | null, "turnDeg" | null, "passed" | null,
//                 "problems": [...]}],
//    "seams": [{"board", "cameras": "front|right", "corners", "rmsCm", "maxCm", "passed"}],
//    "problems": [...] (seams missing or over the limit), "hints": [...],
//    "verdict": null | {"passed", "failures": N},
//    "written": ["path", ...], "error": "..." (empty when none)}
//
// "waiting": not every camera has given a picture yet, or none solved; "failed": the last solve
// failed (the next pictures solve again); "ended": the streams ended before a pass.

#include <string>
#include <vector>

#include "tools/calibrate/guide/mat_guide_session.hpp"

namespace surroundd::calibrate {

// What the session does not know: how the streams and the writing went.
struct MatGuideRunState {
  std::vector<std::string> written;  // files written after the pass
  std::string error;                 // a camera failed, writing failed or was refused: why
  bool ended = false;                // every stream ended
};

std::string matGuideStateJson(const MatGuideSession& session, const MatGuideRunState& run);

}  // namespace surroundd::calibrate
