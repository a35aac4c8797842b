// surround-calibrate import on the three shared pjlab samples (../shared/data; skipped without it),
// as config/rigs/imported/README.md imports them: four cameras in rig order at the heights their
// data README gives, front ahead of back, each looking outward; carla's centres exactly.

#include <array>
#include <cmath>
#include <iostream>
#include <numbers>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "tests/calibration/import_test_support.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd::calibrate {
namespace {

using surroundd::testing::TempDir;

// The shared samples, imported as config/rigs/imported/README.md says.
std::filesystem::path sharedData() {
  return std::filesystem::path(SURROUNDD_SOURCE_DIR) / ".." / "shared" / "data";
}

cv::Vec3d opticalAxis(const CameraCalibration& camera) {
  return camera.pose.rotation * cv::Vec3d(0, 0, 1);
}

// Sensible: four cameras in rig order, heights in range, front ahead of back, left at +y, each
// looking outward (its optical axis within 30 degrees of its side, seen from above).
void expectSensibleRig(const std::vector<daemon::RigCamera>& rig, double minHeight,
                       double maxHeight, const std::string& what) {
  ASSERT_EQ(rig.size(), 4U) << what;
  const std::array<std::pair<const char*, cv::Vec2d>, 4> sides{
      {{"front", {1, 0}}, {"right", {0, -1}}, {"back", {-1, 0}}, {"left", {0, 1}}}};
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& camera = rig[i].calibration;
    const auto& [name, side] = sides[i];
    EXPECT_EQ(camera.name, name) << what;
    EXPECT_GE(camera.pose.position[2], minHeight) << what << " " << name;
    EXPECT_LE(camera.pose.position[2], maxHeight) << what << " " << name;
    const cv::Vec3d axis = opticalAxis(camera);
    const cv::Vec2d flat = cv::normalize(cv::Vec2d(axis[0], axis[1]));
    EXPECT_GT(flat.dot(side), std::cos(30 / kRadToDeg))
        << what << " " << name << " looks along " << axis;
    EXPECT_LT(axis[2], 0.01) << what << " " << name << " looks level or down";
    std::cout << fmt::format(
        "[ measured ] {} {}: ({:+.3f}, {:+.3f}, {:.3f}) m, axis ({:+.2f}, "
        "{:+.2f}, {:+.2f})\n",
        what, name, camera.pose.position[0], camera.pose.position[1], camera.pose.position[2],
        axis[0], axis[1], axis[2]);
  }
  EXPECT_GT(rig[0].calibration.pose.position[0], rig[2].calibration.pose.position[0]) << what;
  EXPECT_GT(rig[3].calibration.pose.position[1], 0) << what;
  EXPECT_LT(rig[1].calibration.pose.position[1], 0) << what;
}

TEST(Import, TheSharedPjlabSamplesGiveSensibleRigs) {
  const auto data = sharedData();
  if (!std::filesystem::is_directory(data)) GTEST_SKIP() << "../shared/data is absent";
  const TempDir dir;
  const auto sample = [&](const char* name) { return (data / name).string(); };

  const auto carla = runImport(
      {"--pjlab", sample("pjlab-carla-pinhole"), "--axes", "right,back,down", "--ground-z", "5.1",
       "--images", sample("pjlab-carla-pinhole/imgs"), "--out", (dir / "carla.yaml").string()});
  expectSensibleRig(carla, 0.99, 1.01, "pjlab-carla-pinhole");
  // The README's centres: front 2.5 m ahead, back 2 m behind, sides 1 m out, all 1.0 m up.
  const std::array<cv::Vec3d, 4> centres{{{2.5, 0, 1}, {0, -1, 1}, {-2, 0, 1}, {0, 1, 1}}};
  for (std::size_t i = 0; i < 4 && i < carla.size(); ++i) {
    EXPECT_LT(cv::norm(carla[i].calibration.pose.position - centres[i]), 0.01)
        << carla[i].calibration.name;
  }

  const auto fisheye = runImport(
      {"--pjlab-yaml", sample("pjlab-fisheye-real/calibration.yaml"), "--lens", "fisheye", "--axes",
       "right,forward,up", "--unit-m", "0.1", "--ground-z", "1", "--origin-centre", "--images",
       sample("pjlab-fisheye-real/imgs"), "--out", (dir / "fisheye.yaml").string()});
  // The calibration's header: about 17 units (1.7 m) up; the back camera sits higher.
  expectSensibleRig(fisheye, 1.5, 2.0, "pjlab-fisheye-real");

  const auto ocam = runImport(
      {"--pjlab", sample("pjlab-ocam-real"), "--lens", "ocam", "--axes", "right,back,down",
       "--ground-z", "front=6.07826,left=6.25217,back=6.31014,right=6.28116", "--origin-centre",
       "--images", sample("pjlab-ocam-real/imgs"), "--out", (dir / "ocam.yaml").string()});
  // The README: camera heights of 1.22-1.35 m follow from the ground heights.
  expectSensibleRig(ocam, 1.21, 1.36, "pjlab-ocam-real");
  for (const auto& camera : ocam) {
    EXPECT_EQ(camera.calibration.intrinsics.model, processing::LensModel::kOcam);
    EXPECT_EQ(camera.calibration.intrinsics.ocam.worldToImage.size(), 11U);
  }
}

}  // namespace
}  // namespace surroundd::calibrate
