#pragma once
// A calibration mat: large checkerboards laid flat around the car at known places, each seen by
// one camera or, as on production-line mats, by two neighbouring cameras at once. The layout is
// given once (tools/calibrate/marker_file.hpp reads it from YAML) and holds for every camera.
//
// A board's pose in a picture is unambiguous only when its two ends look different (one inner
// corner count odd, the other even: processing/calibration/calibration_targets.hpp). A board whose
// counts are both odd or both even looks the same after a half turn, and a square one with even
// counts after a quarter turn too; such boards are identified with the help of the camera's nominal
// pose (see mat_board_detection.hpp for the rule).

#include <string>
#include <vector>

#include "processing/calibration/calibration_targets.hpp"

namespace surroundd::processing {

struct MatBoard {
  GroundMarker print;               // kCheckerboard; its centre, yaw and pattern on the ground
  std::vector<std::string> seenBy;  // the cameras that must find it: one, or two neighbours
};

struct MatLayout {
  std::vector<MatBoard> boards;
};

// The turns that map a board onto itself, colours included.
enum class BoardSymmetry {
  kNone,         // counts of different parity: every corner is told apart by the colours
  kHalfTurn,     // both odd or both even (a square with odd counts: the colours fix quarter turns)
  kQuarterTurn,  // square with even counts: four look-alike orientations
};
BoardSymmetry symmetryOf(const Checkerboard& board);
// "none", "half turn", "quarter turn": for messages.
std::string symmetryName(BoardSymmetry symmetry);

// Indices of the boards that `camera` must find, in layout order.
std::vector<std::size_t> boardsSeenBy(const MatLayout& layout, const std::string& camera);

}  // namespace surroundd::processing
