// A rig file's mounts replaced in place (daemon/config/rig_update.hpp), as the calibration tool's
// --update-rig and surroundctl calibration accept do it: the file reads back to the new mounts,
// every other line stays as written, and a camera the rig lacks changes nothing.

#include "daemon/config/rig_update.hpp"

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "daemon/config/rig_yaml.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {
namespace {

using ::testing::HasSubstr;

const std::filesystem::path kRig =
    std::filesystem::path(SURROUNDD_SOURCE_DIR) / "config/rigs/fisheye-body.yaml";

// The lines of `text` that are not a camera's mount.
std::vector<std::string> linesBesideMounts(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    const std::string line = text.substr(start, end - start);
    if (line.find("mount:") == std::string::npos) lines.push_back(line);
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return lines;
}

TEST(RigUpdate, MountsAreReplacedInPlaceAndReadBack) {
  const testing::TempDir dir;
  const auto rig = dir / "rig.yaml";
  const std::string before = testing::fileBytes(kRig);
  dir.write("rig.yaml", before);
  const auto cameras = loadRigFile(rig);
  processing::Pose turned = cameras.at(2).calibration.pose;
  auto angles = processing::mountAnglesFromRotation(turned.rotation);
  angles.yawDeg -= 1.9;
  turned.rotation = processing::rotationFromMountAngles(angles);
  const std::vector<std::pair<std::string, processing::Pose>> mounts{
      {cameras.at(2).calibration.name, turned}};
  updateRigMounts(rig, mounts, "corrected from the road");

  const auto after = loadRigFile(rig);
  ASSERT_EQ(after.size(), cameras.size());
  for (std::size_t c = 0; c < after.size(); ++c) {
    const auto& expected = c == 2 ? turned : cameras[c].calibration.pose;
    EXPECT_LT(cv::norm(after[c].calibration.pose.rotation - expected.rotation), 1e-9) << c;
    EXPECT_LT(cv::norm(after[c].calibration.pose.position - expected.position), 1e-9) << c;
  }
  const std::string text = testing::fileBytes(rig);
  EXPECT_THAT(text, HasSubstr("# corrected from the road"));
  EXPECT_EQ(linesBesideMounts(text), linesBesideMounts(before));
  EXPECT_FALSE(std::filesystem::exists(dir / "rig.yaml.part"));
}

TEST(RigUpdate, ACameraTheRigLacksChangesNothing) {
  const testing::TempDir dir;
  const std::string before = testing::fileBytes(kRig);
  dir.write("rig.yaml", before);
  const std::vector<std::pair<std::string, processing::Pose>> mounts{{"roof", {}}};
  try {
    updateRigMounts(dir / "rig.yaml", mounts, "");
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("has no camera 'roof' (it has front, right, back, left)"));
  }
  EXPECT_EQ(testing::fileBytes(dir / "rig.yaml"), before);
}

}  // namespace
}  // namespace surroundd::daemon
