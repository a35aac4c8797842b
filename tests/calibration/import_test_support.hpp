#pragma once
// Shared by the import tests: the rig presets, a foreign frame to write them in, running the
// importer, and how close an imported rig must come to the truth.

#include <cctype>
#include <cmath>
#include <iostream>
#include <numbers>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "daemon/config/rig_yaml.hpp"
#include "processing/rig.hpp"
#include "tools/calibrate/calibrate_options.hpp"
#include "tools/calibrate/import/import_command.hpp"

namespace surroundd::calibrate {

using processing::CameraCalibration;

inline constexpr double kRadToDeg = 180 / std::numbers::pi;

inline std::vector<CameraCalibration> preset(const std::string& name) {
  std::vector<CameraCalibration> cameras;
  for (const auto& camera :
       daemon::loadRigFile(std::string(SURROUNDD_SOURCE_DIR) + "/config/rigs/" + name)) {
    cameras.push_back(camera.calibration);
  }
  return cameras;
}

// A frame as another tool might use: axes, unit, where the ground is on its vertical axis, and
// the vehicle-frame ground point under its origin.
struct ForeignFrame {
  std::string axesText;
  cv::Matx33d axes;  // columns: source x, y, z in the vehicle frame
  double unitM;
  double groundZ;
  cv::Vec3d originOnGround;

  cv::Vec3d toSource(const cv::Vec3d& vehicle) const {
    cv::Vec3d source = axes.t() * (vehicle - originOnGround) * (1 / unitM);
    for (int k = 0; k < 3; ++k) {
      if (std::abs(axes(2, k)) > 0.5) source[k] += groundZ;
    }
    return source;
  }
  // P_camera = rotation * P_source + translation.
  std::pair<cv::Matx33d, cv::Vec3d> cameraFromSource(const processing::Pose& pose) const {
    const cv::Matx33d rotation = pose.rotation.t() * axes;
    return {rotation, -(rotation * toSource(pose.position))};
  }
  std::vector<std::string> options() const {
    return {"--axes",     axesText,
            "--unit-m",   fmt::format("{}", unitM),
            "--ground-z", fmt::format("{:.17g}", groundZ),
            "--offset-m", fmt::format("{:.17g},{:.17g},0", originOnGround[0], originOnGround[1])};
  }
};

// A top-down frame (x right, y towards the rear, z down) in decimetres, its origin 5 m above the
// ground at vehicle (0.7, -0.4): the pjlab samples' kind of frame, off-centre.
inline const ForeignFrame kTopDown{
    "right,back,down", {0, -1, 0, -1, 0, 0, 0, 0, -1}, 0.1, 50, {0.7, -0.4, 0}};

inline ImportedRig importWith(const std::vector<std::string>& arguments) {
  const std::vector<std::string_view> views(arguments.begin(), arguments.end());
  return importRig(parseImport(views));
}

inline std::vector<daemon::RigCamera> runImport(const std::vector<std::string>& arguments) {
  return importWith(arguments).cameras;
}

inline std::string fileName(const CameraCalibration& camera) {
  auto name = camera.name;
  name[0] = static_cast<char>(std::toupper(name[0]));
  return name;
}

// Poses within 1 cm and 0.2 degrees; prints the worst for the record.
inline void expectPoses(const std::vector<daemon::RigCamera>& imported,
                        const std::vector<CameraCalibration>& truth, const std::string& what) {
  ASSERT_EQ(imported.size(), truth.size()) << what;
  double worstM = 0, worstDeg = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const auto& got = imported[i].calibration;
    const auto& want = truth[i];
    EXPECT_EQ(got.name, want.name) << what << ": the rig order is front, right, back, left";
    cv::Vec3d turn;
    cv::Rodrigues(got.pose.rotation * want.pose.rotation.t(), turn);
    const double metres = cv::norm(got.pose.position - want.pose.position);
    const double degrees = cv::norm(turn) * kRadToDeg;
    EXPECT_LT(metres, 0.01) << what << " " << want.name;
    EXPECT_LT(degrees, 0.2) << what << " " << want.name;
    EXPECT_EQ(got.role, want.role) << what << " " << want.name;
    worstM = std::max(worstM, metres);
    worstDeg = std::max(worstDeg, degrees);
  }
  std::cout << fmt::format("[ measured ] {}: worst position {:.2e} m, rotation {:.2e} deg\n", what,
                           worstM, worstDeg);
}

inline void expectSameLens(const processing::Intrinsics& got, const processing::Intrinsics& want,
                           const std::string& what) {
  EXPECT_EQ(got.model, want.model) << what;
  EXPECT_EQ(got.imageSize, want.imageSize) << what;
  EXPECT_DOUBLE_EQ(got.fx, want.fx) << what;
  EXPECT_DOUBLE_EQ(got.fy, want.fy) << what;
  EXPECT_DOUBLE_EQ(got.cx, want.cx) << what;
  EXPECT_DOUBLE_EQ(got.cy, want.cy) << what;
  for (std::size_t i = 0; i < 5; ++i) EXPECT_DOUBLE_EQ(got.distortion[i], want.distortion[i]);
}

inline cv::Mat cameraMatrix(const processing::Intrinsics& lens) {
  return (cv::Mat_<double>(3, 3) << lens.fx, 0, lens.cx, 0, lens.fy, lens.cy, 0, 0, 1);
}

}  // namespace surroundd::calibrate
