// Issue 48, end to end: surroundd replaying a generated drive corrects a camera's mount on the
// road (calibration_watch.correct: apply), and surroundctl calibration accept writes it into the
// rig file.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "processing/calibration/mount_refinement.hpp"
#include "tests/daemon/service_test_support.hpp"

namespace surroundd::daemon {
namespace {

using ::testing::HasSubstr;

// The generated fisheye drive, looping, under a rig that says its back camera's yaw is 2 degrees
// more than it was, with calibration_watch.correct: apply, replayed as fast as it goes.
class CalibrationAcceptTest : public ServiceTest {
 protected:
  // After the service's own set-up, which writes the small recording's rig.
  void SetUp() override {
    ServiceTest::SetUp();
    const auto drive = std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_drive_fisheye_hd";
    cameras_ = loadRigFile(drive / "rig.yaml");
    const YAML::Node truth = YAML::LoadFile((drive / "ground_truth.yaml").string());
    for (std::size_t c = 0; c < cameras_.size(); ++c) {
      cameras_[c].replayedFile()->loop = true;
      cameras_[c].bodyMask =
          BodyMaskConfig{BodyMaskConfig::Mode::kReplace,
                         drive / truth["cameras"][c]["body_mask"].as<std::string>(),
                         {}};
    }
    trueBack_ = cameras_[kBack].calibration.pose;
    auto& back = cameras_[kBack].calibration.pose;
    auto angles = processing::mountAnglesFromRotation(back.rotation);
    angles.yawDeg += 2;
    back.rotation = processing::rotationFromMountAngles(angles);
    writeRigFile(dir_ / "rig.yaml", cameras_, "the drive's, its back camera's yaw 2 degrees off");
  }

  static constexpr const char* kOutputs =
      "  - {type: snapshot, stream: panorama, path: out/panorama.png, at_s: 1000}";
  static constexpr const char* kWatch =
      "capture: {pacing: as_fast_as_possible}\n"
      "calibration_watch: {interval_s: 0.5, correct: apply, compare_every_s: 0.5}";

  // Waits until the watch has made its correction and kept it (120 s at most).
  void waitForTheCorrection(testing::ChildProcess& surroundd) const {
    std::string status;
    for (auto deadline = std::chrono::steady_clock::now() + 120s;
         std::chrono::steady_clock::now() < deadline && surroundd.running();
         std::this_thread::sleep_for(200ms)) {
      if (!std::filesystem::exists(socket_)) continue;
      status = request("calibration").body;
      if (status.find("corrections applied 1, taken back 0\n") != std::string::npos) return;
    }
    ADD_FAILURE() << "no correction kept: " << status << surroundd.output();
  }

  static constexpr std::size_t kBack = 2;
  std::vector<RigCamera> cameras_;
  processing::Pose trueBack_;
};

// `surroundctl calibration accept` writes the corrected mount into the rig file in place (the
// file before kept beside it) and nothing else; a second accept has nothing to write, and a revert
// nothing to take back.
TEST_F(CalibrationAcceptTest, TheCorrectedMountIsWrittenIntoTheRigFile) {
  const std::string rigBefore = testing::fileBytes(dir_ / "rig.yaml");
  auto surroundd = start(writeConfig(kOutputs, kWatch));
  waitForTheCorrection(*surroundd);

  testing::ChildProcess accept(
      {SURROUNDCTL_EXECUTABLE, "--socket", socket_.string(), "calibration", "accept"},
      dir_ / "accept.txt");
  EXPECT_EQ(accept.wait(), 0) << accept.output();
  EXPECT_THAT(accept.output(), HasSubstr("wrote the corrected mount of camera 'back' into"));
  EXPECT_EQ(testing::fileBytes(dir_ / "rig.yaml.before-accept"), rigBefore);
  const auto accepted = loadRigFile(dir_ / "rig.yaml");
  ASSERT_EQ(accepted.size(), cameras_.size());
  for (std::size_t c = 0; c < accepted.size(); ++c) {
    const processing::Pose& expected = c == kBack ? trueBack_ : cameras_[c].calibration.pose;
    const auto off = processing::mountAngleChange(expected, accepted[c].calibration.pose);
    EXPECT_LT(std::abs(off.yawDeg) + std::abs(off.pitchDeg) + std::abs(off.rollDeg),
              c == kBack ? 0.3 : 1e-9)
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

// A config that writes its cameras inline has no rig file to write into: accept says so and
// gives the corrected mount to copy, and writes nothing.
TEST_F(CalibrationAcceptTest, ACameraWrittenInlineGetsItsMountToCopy) {
  std::string inlined = "rig:\n";
  const std::string rig = testing::fileBytes(dir_ / "rig.yaml");
  for (std::size_t start = 0; start < rig.size();) {
    const std::size_t end = std::min(rig.find('\n', start), rig.size());
    inlined += "  " + rig.substr(start, end - start) + "\n";
    start = end + 1;
  }
  const std::string config = testing::fileBytes(writeConfig(kOutputs, kWatch));
  const std::string fileLine = "rig: {file: rig.yaml}\n";
  const auto inlineConfig = dir_.write(
      "inline.yaml", std::string(config).replace(config.find(fileLine), fileLine.size(), inlined));
  std::filesystem::remove(dir_ / "rig.yaml");
  auto surroundd = start(inlineConfig);
  waitForTheCorrection(*surroundd);

  const auto accept = request("calibration accept");
  EXPECT_FALSE(accept.ok);
  EXPECT_THAT(accept.body,
              HasSubstr("inline.yaml writes its cameras inline, not in a rig file: "
                        "nothing is written; copy them: camera 'back': mount: {x_m: "));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "rig.yaml"));

  surroundd->signal(SIGTERM);
  EXPECT_EQ(surroundd->wait(), 0) << surroundd->output();
}

}  // namespace
}  // namespace surroundd::daemon
