// The drift watch's verdict: a camera is named only when the ground under all of its seams is
// measured and too far apart; one misaligned seam alone cannot say which of its cameras moved.

#include <gtest/gtest.h>

#include "daemon/stages/calibration_watch_stage.hpp"

namespace surroundd::daemon {
namespace {

// Four cameras in a ring (front 0, right 1, back 2, left 3) and their four seams.
std::vector<SeamShift> ring(std::optional<double> frontRight, std::optional<double> rightBack,
                            std::optional<double> backLeft, std::optional<double> leftFront) {
  return {{0, 1, frontRight}, {1, 2, rightBack}, {2, 3, backLeft}, {3, 0, leftFront}};
}

TEST(CalibrationWatch, ACameraIsNamedOnlyWhenAllItsSeamsAreMeasuredAndTooFarApart) {
  // The front camera knocked: both its seams move, the others stay.
  EXPECT_EQ(driftingCameras(4, ring(13.4, 0.1, 0.1, 13.5), 5),
            (std::vector<bool>{true, false, false, false}));
  // One misaligned seam whose neighbour could not be measured (too little texture): no verdict.
  EXPECT_EQ(driftingCameras(4, ring(std::nullopt, 10.7, std::nullopt, 0.5), 5),
            (std::vector<bool>{false, false, false, false}));
  // One misaligned seam, both neighbours fine: neither of its cameras is named.
  EXPECT_EQ(driftingCameras(4, ring(0.2, 10.7, 0.3, 0.5), 5),
            (std::vector<bool>{false, false, false, false}));
  // A calibration off everywhere names every camera; exactly at the threshold is not past it.
  EXPECT_EQ(driftingCameras(4, ring(8, 8, 8, 8), 5), (std::vector<bool>{true, true, true, true}));
  EXPECT_EQ(driftingCameras(4, ring(5, 5, 5, 5), 5),
            (std::vector<bool>{false, false, false, false}));
  // A camera with no seam watched (its ground not seen by a neighbour) is never named.
  EXPECT_EQ(driftingCameras(5, ring(13.4, 0.1, 0.1, 13.5), 5),
            (std::vector<bool>{true, false, false, false, false}));
}

}  // namespace
}  // namespace surroundd::daemon
