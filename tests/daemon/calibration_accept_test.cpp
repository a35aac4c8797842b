// Issue 48, end to end: surroundd replaying a generated drive corrects a camera's mount on the
// road (calibration_watch.correct: apply), and surroundctl calibration accept writes it into the
// rig file.

#include <cmath>
#include <filesystem>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "processing/calibration/mount_refinement.hpp"
#include "tests/daemon/service_test_support.hpp"

namespace surroundd::daemon {
namespace {

using ::testing::HasSubstr;

// Issue 48: the generated fisheye drive, looping, under a rig that says its back camera's yaw is
// 2 degrees more than it was. With calibration_watch.correct: apply the watch corrects it while the
// daemon runs; `surroundctl calibration accept` then writes the corrected mount into the rig file
// in place (the file before kept beside it) and nothing else; a second accept has nothing to
// write, and a revert nothing to take back.
TEST_F(ServiceTest, ACorrectionAppliedOnTheRoadIsAcceptedIntoTheRigFile) {
  const auto drive = std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_drive_fisheye_hd";
  auto cameras = loadRigFile(drive / "rig.yaml");
  const YAML::Node truth = YAML::LoadFile((drive / "ground_truth.yaml").string());
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    cameras[c].replayedFile()->loop = true;
    cameras[c].bodyMask = BodyMaskConfig{BodyMaskConfig::Mode::kReplace,
                                         drive / truth["cameras"][c]["body_mask"].as<std::string>(),
                                         {}};
  }
  const processing::Pose trueBack = cameras[2].calibration.pose;
  auto& back = cameras[2].calibration.pose;
  auto angles = processing::mountAnglesFromRotation(back.rotation);
  angles.yawDeg += 2;
  back.rotation = processing::rotationFromMountAngles(angles);
  writeRigFile(dir_ / "rig.yaml", cameras, "the drive's, its back camera's yaw 2 degrees off");
  const std::string rigBefore = testing::fileBytes(dir_ / "rig.yaml");
  auto surroundd = start(
      writeConfig("  - {type: snapshot, stream: panorama, path: out/panorama.png, at_s: 1000}",
                  "capture: {pacing: as_fast_as_possible}\n"
                  "calibration_watch: {interval_s: 0.5, correct: apply, compare_every_s: 0.5}"));

  std::string status;
  for (auto deadline = std::chrono::steady_clock::now() + 120s;
       std::chrono::steady_clock::now() < deadline && surroundd->running();
       std::this_thread::sleep_for(200ms)) {
    if (!std::filesystem::exists(socket_)) continue;
    status = request("calibration").body;
    if (status.find("corrections applied 1, taken back 0\n") != std::string::npos) break;
  }
  ASSERT_THAT(status, HasSubstr("corrections applied 1, taken back 0\n")) << surroundd->output();

  testing::ChildProcess accept(
      {SURROUNDCTL_EXECUTABLE, "--socket", socket_.string(), "calibration", "accept"},
      dir_ / "accept.txt");
  EXPECT_EQ(accept.wait(), 0) << accept.output();
  EXPECT_THAT(accept.output(), HasSubstr("wrote the corrected mount of camera 'back' into"));
  EXPECT_EQ(testing::fileBytes(dir_ / "rig.yaml.before-accept"), rigBefore);
  const auto accepted = loadRigFile(dir_ / "rig.yaml");
  ASSERT_EQ(accepted.size(), cameras.size());
  for (std::size_t c = 0; c < accepted.size(); ++c) {
    const processing::Pose& expected = c == 2 ? trueBack : cameras[c].calibration.pose;
    const auto off = processing::mountAngleChange(expected, accepted[c].calibration.pose);
    EXPECT_LT(std::abs(off.yawDeg) + std::abs(off.pitchDeg) + std::abs(off.rollDeg),
              c == 2 ? 0.3 : 1e-9)
        << accepted[c].calibration.name;
  }
  EXPECT_THAT(testing::fileBytes(dir_ / "rig.yaml"),
              HasSubstr("# corrected from the road by surroundd's calibration watch, accepted"));

  const auto again = request("calibration accept");
  EXPECT_FALSE(again.ok);
  EXPECT_THAT(again.body, HasSubstr("nothing to accept"));
  const auto revert = request("calibration revert");
  EXPECT_TRUE(revert.ok) << revert.body;
  EXPECT_THAT(revert.body, HasSubstr("nothing to take back"));

  surroundd->signal(SIGTERM);
  EXPECT_EQ(surroundd->wait(), 0) << surroundd->output();
}

}  // namespace
}  // namespace surroundd::daemon
