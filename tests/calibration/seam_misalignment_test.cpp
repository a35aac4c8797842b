// The calibration-drift measure on a generated recording of the paper rig (synth_seams, 4 x 1280
// wide, noise-free frames): with the calibration that rendered it every seam's ground agrees to a
// few millimetres; with the front camera's calibration turned by 1 and 2 degrees (what a knocked
// camera looks like against an unchanged calibration), the ground under both of its seams moves
// by its distance from that camera times the angle, and under the other seams not at all.

#include "processing/calibration/seam_misalignment.hpp"

#include <cmath>
#include <filesystem>
#include <numbers>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "tools/bench/recording_truth.hpp"

namespace surroundd::processing {
namespace {

cv::Matx33d yawBy(double degrees) {
  const double a = degrees * std::numbers::pi / 180;
  return {std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1};
}

class SeamMisalignmentTest : public ::testing::Test {
 protected:
  SeamMisalignmentTest()
      : truth_(bench::loadRecordingTruth(std::filesystem::path(SURROUNDD_FIXTURE_DIR) /
                                         "synth_seams")) {
    settings_.geometry = truth_.panorama;
    for (const auto& path : truth_.frames.front().images) frames_.push_back(cv::imread(path));
  }

  bench::RecordingTruth truth_;
  PanoramaSettings settings_;
  std::vector<cv::Mat> frames_;
};

TEST_F(SeamMisalignmentTest, TheTrueCalibrationAgreesUnderEverySeam) {
  const auto seams = seamLines(truth_.rig, settings_);
  ASSERT_EQ(seams.size(), 4u);
  for (const auto& seam : seams) {
    const auto measured = seamMisalignment(truth_.rig, frames_, settings_, seam);
    ASSERT_TRUE(measured) << seam.name;
    EXPECT_LT(measured->shiftCm, 1.0) << seam.name;
    EXPECT_GT(measured->response, 0.3) << seam.name;
  }
}

TEST_F(SeamMisalignmentTest, ACameraTurnedByOneOrTwoDegreesMovesTheGroundUnderItsSeams) {
  const std::size_t front = 0;
  ASSERT_EQ(truth_.rig.cameras[front].name, "front");
  const auto seams = seamLines(truth_.rig, settings_);
  for (const double degrees : {1.0, 2.0}) {
    Rig knocked = truth_.rig;
    knocked.cameras[front].pose.rotation = yawBy(degrees) * knocked.cameras[front].pose.rotation;
    for (const auto& seam : seams) {
      SCOPED_TRACE(::testing::Message() << seam.name << ", " << degrees << " deg");
      auto probe = SeamMisalignmentProbe::make(knocked, settings_, seam);
      ASSERT_TRUE(probe);
      const SeamMisalignment measured = probe->measure(frames_[seam.left], frames_[seam.right]);
      EXPECT_GT(measured.response, 0.3);
      if (seam.left != front && seam.right != front) {
        EXPECT_LT(measured.shiftCm, 1.0);
        continue;
      }
      // The patch's centre, and its distance from the turned camera across the ground.
      const cv::Vec3d camera = knocked.cameras[front].pose.position;
      const double distance =
          std::hypot(probe->distanceM() * std::cos(seam.azimuthRad) - camera[0],
                     probe->distanceM() * std::sin(seam.azimuthRad) - camera[1]);
      const double expectedCm = distance * degrees * std::numbers::pi / 180 * 100;
      EXPECT_NEAR(measured.shiftCm, expectedCm, 0.15 * expectedCm);
      RecordProperty(fmt::format("shift_cm_{}deg_{}", degrees, seam.name),
                     fmt::format("{:.2f} (expected {:.2f})", measured.shiftCm, expectedCm));
    }
  }
}

}  // namespace
}  // namespace surroundd::processing
