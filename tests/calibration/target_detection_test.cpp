// Target detection on rendered pictures with known corners: a checkerboard's corners come in the
// board's own order however it is turned, several boards of one pattern are all found, and an
// ArUco marker gives its id and its corners clockwise from its top left.

#include "processing/calibration/target_detection.hpp"

#include <numbers>

#include <gtest/gtest.h>

#include "tests/calibration/calibration_test_support.hpp"

namespace surroundd::calibration::testing {
namespace {

const processing::Checkerboard kBoard{{7, 4}, 0.04};

// A board facing the camera 0.6 m ahead, turned `rollDeg` about its normal, centred at `offset`.
processing::Pose facingBoard(double rollDeg, const cv::Vec3d& offset = {0, 0, 0}) {
  const double roll = rollDeg * std::numbers::pi / 180;
  processing::Pose pose;
  pose.rotation =
      cv::Matx33d(std::cos(roll), -std::sin(roll), 0, std::sin(roll), std::cos(roll), 0, 0, 0, 1);
  const cv::Vec3d centre((kBoard.innerCorners.width - 1) * kBoard.squareM / 2,
                         (kBoard.innerCorners.height - 1) * kBoard.squareM / 2, 0);
  pose.position = cv::Vec3d(0, 0, 0.6) + offset - pose.rotation * centre;
  return pose;
}

double worstCornerError(const std::vector<cv::Point2f>& found, const processing::Pose& pose,
                        const processing::CameraModel& model) {
  const auto pattern = kBoard.patternCorners();
  double worst = 0;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    const auto truth = model.project(pose.toVehicle({pattern[i].x, pattern[i].y, 0}));
    worst = std::max(worst, cv::norm(cv::Point2d(found[i]) - *truth));
  }
  return worst;
}

TEST(TargetDetection, BoardCornersComeInTheBoardsOrderHoweverItIsTurned) {
  const auto lens = presetCameras("paper.yaml").front().intrinsics;
  const processing::CameraModel model(lens);
  const synth::TargetRenderer renderer(lens, kSupersampling);
  for (const double roll : {0.0, 30.0, 90.0, 160.0, 180.0, 270.0}) {
    SCOPED_TRACE(roll);
    const auto pose = facingBoard(roll);
    const synth::TargetScene scene{{synth::placeBoard(kBoard, pose)}, false};
    const auto corners = processing::findCheckerboard(
        toGray(renderer.render({}, scene, sensor(0), 1, 0)), kBoard.innerCorners);
    ASSERT_TRUE(corners);
    EXPECT_LT(worstCornerError(*corners, pose, model), 0.3);
  }
}

TEST(TargetDetection, EveryBoardOfOnePatternIsFound) {
  const auto lens = presetCameras("paper.yaml").front().intrinsics;
  const processing::CameraModel model(lens);
  std::vector<processing::Pose> poses;
  synth::TargetScene scene;
  for (const double x : {-0.5, 0.0, 0.5}) {
    poses.push_back(facingBoard(x * 60, {x, 0, 0.6}));
    scene.targets.push_back(synth::placeBoard(kBoard, poses.back()));
  }
  const synth::TargetRenderer renderer(lens, kSupersampling);
  const auto boards = processing::findCheckerboards(
      toGray(renderer.render({}, scene, sensor(0), 1, 0)), kBoard.innerCorners, 5);
  ASSERT_EQ(boards.size(), 3u);
  for (const auto& corners : boards) {
    double best = 1e9;
    for (const auto& pose : poses) best = std::min(best, worstCornerError(corners, pose, model));
    EXPECT_LT(best, 0.3);
  }
}

TEST(TargetDetection, ArucoMarkerGivesItsIdAndCornersInOrder) {
  const auto lens = presetCameras("fisheye.yaml").front().intrinsics;
  const processing::CameraModel model(lens);
  const synth::TargetRenderer renderer(lens, kSupersampling);
  processing::CameraCalibration camera;
  camera.intrinsics = lens;
  camera.pose.rotation = processing::rotationFromMountAngles({0, -60, 0});
  camera.pose.position = {0, 0, 1.0};
  processing::GroundMarker marker;
  marker.kind = processing::MarkerKind::kAruco;
  marker.arucoId = 7;
  marker.arucoSideM = 0.3;
  marker.centre = {0.6, 0.1, 0};
  marker.yawDeg = 120;
  const int dictionary = *processing::arucoDictionaryByName("4x4_50");
  const synth::TargetScene scene{{synth::placeGroundMarker(marker, dictionary)}, true};
  const auto found = processing::findArucoMarkers(
      toGray(renderer.render(camera.pose, scene, sensor(0), 1, 0)), dictionary);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].id, 7);
  const auto corners = marker.corners();
  for (std::size_t k = 0; k < 4; ++k) {
    const auto truth = model.project(camera.pose.toCamera(cv::Vec3d(corners[k])));
    EXPECT_LT(cv::norm(cv::Point2d(found[0].corners[k]) - *truth), 0.5) << "corner " << k;
  }
}

}  // namespace
}  // namespace surroundd::calibration::testing
