#pragma once
// Shared by the calibration tests: the rig presets at test size, the generator's calibration
// pictures (checkerboard views, ground markers) with their truth, and how far a result is off.

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "daemon/config/rig_yaml.hpp"
#include "processing/calibration/calibration_error.hpp"
#include "processing/calibration/calibration_targets.hpp"
#include "processing/rig.hpp"
#include "tools/synth/calibration_mat.hpp"
#include "tools/synth/calibration_scenes.hpp"
#include "tools/synth/recording_plan.hpp"
#include "tools/synth/target_renderer.hpp"

namespace surroundd::calibration::testing {

// Small images keep the tests quick; the accuracy asked for holds at this size.
inline const cv::Size kTestSize{640, 360};
inline constexpr int kSupersampling = 3;
// Roof cameras see the ground from 1.2 m out, the grille camera from 0.6 m up: most of it far or
// at a grazing angle. At 960x540 enough markers there are large enough to find.
inline const cv::Size kGroundViewSize{960, 540};

inline std::string rigPreset(const std::string& name) {
  return std::string(SURROUNDD_SOURCE_DIR) + "/config/rigs/" + name;
}

// The preset's cameras with their lenses scaled to `size`.
inline std::vector<processing::CameraCalibration> presetCameras(const std::string& name,
                                                                cv::Size size = kTestSize) {
  std::vector<processing::CameraCalibration> cameras;
  for (const auto& camera : daemon::loadRigFile(rigPreset(name))) {
    cameras.push_back(camera.calibration);
    cameras.back().intrinsics = synth::scaleIntrinsics(camera.calibration.intrinsics, size);
  }
  return cameras;
}

// A real sensor: gain, white balance, gamma, vignetting and 1.5 levels of noise.
inline synth::CameraPhotometrics sensor(int index) {
  return synth::randomPhotometrics(17, index, 1.5, false);
}

inline cv::Mat toGray(const cv::Mat& bgr) {
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  return gray;
}

// Checkerboard views covering the field of `lens`, as 8-bit BGR images.
inline std::vector<cv::Mat> boardViews(const processing::Intrinsics& lens,
                                       const processing::Checkerboard& board, int count,
                                       std::uint64_t seed) {
  const synth::TargetRenderer renderer(lens, kSupersampling);
  std::vector<cv::Mat> images;
  int frame = 0;
  for (const auto& pose : synth::boardPosesCoveringField(lens, board, count, seed)) {
    synth::TargetScene scene;
    scene.targets.push_back(synth::placeBoard(board, pose));
    images.push_back(renderer.render({}, scene, sensor(0), seed, frame++));
  }
  return images;
}

// What a rig camera sees of a ground marker layout: the floor, the markers, the sky.
inline cv::Mat groundView(const processing::CameraCalibration& camera,
                          const processing::MarkerLayout& layout, std::uint64_t seed) {
  const synth::TargetRenderer renderer(camera.intrinsics, kSupersampling);
  synth::TargetScene scene;
  scene.floor = true;
  for (const auto& marker : layout.markers) {
    scene.targets.push_back(synth::placeGroundMarker(marker, layout.arucoDictionary));
  }
  return renderer.render(camera.pose, scene, sensor(1), seed, 0);
}

// Three 5x4 boards and three ArUco markers (4x4_50) where a camera looks.
inline synth::GroundMarkerRequest groundMarkers(double squareM, double arucoSideM) {
  synth::GroundMarkerRequest request;
  request.boards = 3;
  request.board = {{5, 4}, squareM};
  request.arucoMarkers = 3;
  request.arucoSideM = arucoSideM;
  return request;
}

// `call` must throw processing::CalibrationError with exactly `message`.
template <typename Call>
void expectCalibrationError(Call call, const std::string& message) {
  try {
    call();
    ADD_FAILURE() << "no CalibrationError; expected: " << message;
  } catch (const processing::CalibrationError& error) {
    EXPECT_EQ(error.what(), message);
  }
}

struct PoseError {
  double positionCm = 0;
  double rotationDeg = 0;
};

inline PoseError poseError(const processing::Pose& solved, const processing::Pose& truth) {
  cv::Vec3d turn;
  cv::Rodrigues(solved.rotation * truth.rotation.t(), turn);
  return {100 * cv::norm(solved.position - truth.position),
          cv::norm(turn) * 180 / std::numbers::pi};
}

// A pose a few centimetres and degrees off: what a rig file says before calibration.
inline processing::Pose nominal(const processing::Pose& truth) {
  return synth::mountMeasuredByHand(truth);
}

}  // namespace surroundd::calibration::testing
