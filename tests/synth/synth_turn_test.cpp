// surround-synth --turn: a camera knocked mid-recording (synth_turn: the fisheye rig's back camera
// pitched 3 degrees from 2 s on). The truth file says when and the mount after; the recording's
// rig keeps the mount before; under the back camera's seams the ground agrees through the rig's
// mount before the turn, is centimetres apart after it, and agrees again through the mount after.

#include <filesystem>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "processing/calibration/seam_misalignment.hpp"
#include "tests/support/test_support.hpp"
#include "tools/bench/recording_truth.hpp"

namespace surroundd::processing {
namespace {

const std::filesystem::path kTurn = std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_turn";

// The larger shift under the back camera's two seams, centimetres.
double backSeamsApart(const Rig& rig, const PanoramaSettings& settings,
                      const std::vector<cv::Mat>& frames) {
  double largest = 0;
  for (const SeamLine& seam : seamLines(rig, settings)) {
    if (seam.name.find("back") == std::string::npos) continue;
    const auto measured = seamMisalignment(rig, frames, settings, seam);
    EXPECT_TRUE(measured) << seam.name;
    if (measured) largest = std::max(largest, measured->shiftCm);
  }
  return largest;
}

TEST(SynthTurn, KnocksTheCameraAtItsTimeAndSaysItsMountAfter) {
  const bench::RecordingTruth truth = bench::loadRecordingTruth(kTurn);
  const YAML::Node written = YAML::LoadFile((kTurn / "ground_truth.yaml").string());
  const YAML::Node back = written["cameras"][2];
  ASSERT_EQ(back["name"].as<std::string>(), "back");
  EXPECT_DOUBLE_EQ(back["turned_at_s"].as<double>(), 2.0);
  const MountAngles before = mountAnglesFromRotation(truth.rig.cameras[2].pose.rotation);
  const YAML::Node after = back["mount_after_turn"];
  EXPECT_NEAR(after["pitch_deg"].as<double>(), before.pitchDeg + 3, 1e-9);
  EXPECT_NEAR(after["yaw_deg"].as<double>(), before.yawDeg, 1e-9);
  EXPECT_TRUE(std::filesystem::exists(kTurn / back["body_mask_after_turn"].as<std::string>()));

  std::vector<std::vector<cv::Mat>> frames(2);  // the first set and the last
  for (const CameraCalibration& camera : truth.rig.cameras) {
    const auto pictures = testing::decodeAll(kTurn / (camera.name + ".mkv")).images;
    frames[0].push_back(pictures.front());
    frames[1].push_back(pictures.back());
  }
  PanoramaSettings settings;
  settings.geometry = truth.panorama;
  Rig turned = truth.rig;
  turned.cameras[2].pose.rotation =
      rotationFromMountAngles({after["yaw_deg"].as<double>(), after["pitch_deg"].as<double>(),
                               after["roll_deg"].as<double>()});
  // 1.0, 16.5 and 1.7 cm when written.
  EXPECT_LT(backSeamsApart(truth.rig, settings, frames[0]), 2.0);
  EXPECT_GT(backSeamsApart(truth.rig, settings, frames[1]), 10.0);
  EXPECT_LT(backSeamsApart(turned, settings, frames[1]), 2.0);
}

}  // namespace
}  // namespace surroundd::processing
