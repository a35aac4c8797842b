#pragma once
// The guided calibration's state as the JSON the page reads (/state.json), so that the page
// only draws: the kept views with their outlines, the coverage cells, the hints, the last
// frame's outcome and the verdict.
//
//   {"phase": "collecting" | "passed" | "ended", "board": "9x6 chessboard", "model": "fisheye",
//    "image": {"width": W, "height": H}, "frames": N, "streamTimeS": T,
//    "views": [{"name", "timeS", "corners", "edgePx", "outline": [[x, y], ...]}],
//    "coverage": {"columns", "rows", "share", "needed", "cells": [row-major: corner count, or
//                 -1 outside the lens]},
//    "minViews": N, "hints": ["..."], "last": {"outcome", "note"},
//    "verdict": null | {"passed", "failures": [...], "rmsPx", "fx", "fy", "cx", "cy", "views",
//                       "leftOut": [...], "fieldOfViewDeg"},
//    "passedAtS": T | null, "written": ["path", ...], "error": "..." (empty when none)}

#include <chrono>
#include <string>
#include <vector>

#include "tools/calibrate/guide/guide_session.hpp"

namespace surroundd::calibrate {

// What the session does not know: how the stream and the writing went.
struct GuideRunState {
  std::chrono::nanoseconds streamTime{0};  // of the newest frame
  FrameResult last;                        // the newest frame's outcome
  std::vector<std::string> written;        // files written after the pass
  std::string error;                       // the camera failed or ended, writing failed: why
  bool ended = false;                      // the stream ended (a file that does not loop)
};

std::string guideStateJson(const GuideSession& session, const GuideRunState& run);

// `text` as a JSON string, quotes included.
std::string jsonString(std::string_view text);
// `items` as a JSON array of strings.
std::string jsonStringArray(const std::vector<std::string>& items);

}  // namespace surroundd::calibrate
