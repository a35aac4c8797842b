// Camera poses from ground markers that the generator lays out where each camera of a rig preset
// looks and renders through its lens: every camera's pose must come out within 1 cm and 0.2
// degrees of the truth, for the paper's pinhole rig and the 190-degree fisheye rig, starting from
// a rig file that is a few centimetres and degrees off.

#include <numbers>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "processing/calibration/extrinsic_calibration.hpp"
#include "processing/calibration/ground_marker_detection.hpp"
#include "tests/calibration/calibration_test_support.hpp"
#include "tools/synth/hash.hpp"

namespace surroundd::calibration::testing {
namespace {

struct Solved {
  std::size_t markersFound = 0;
  processing::ExtrinsicCalibration calibration;
};

Solved solveFromMarkers(const processing::CameraCalibration& camera,
                        const processing::MarkerLayout& layout, std::uint64_t seed) {
  const cv::Mat gray = toGray(groundView(camera, layout, seed));
  const processing::CameraModel model(camera.intrinsics);
  const auto sightings = processing::findGroundMarkers(gray, layout, model, nominal(camera.pose));
  const auto points = processing::correspondencesOf(layout, sightings);
  return {sightings.size(), processing::calibrateExtrinsics(camera.intrinsics, points)};
}

void expectEveryCameraPosed(const std::string& preset, cv::Size size,
                            const synth::GroundMarkerRequest& base) {
  double worstCm = 0, worstDeg = 0, worstRms = 0;
  std::size_t placed = 0, found = 0;
  std::uint64_t seed = 1;
  for (const auto& camera : presetCameras(preset, size)) {
    SCOPED_TRACE(camera.name);
    auto request = base;
    request.seed = ++seed;
    const auto layout = synth::groundMarkersInView(camera, request);
    ASSERT_GE(layout.markers.size(), 3u) << "the generator found room for too few markers";
    const Solved solved = solveFromMarkers(camera, layout, seed);
    EXPECT_GE(solved.markersFound + 1, layout.markers.size());
    placed += layout.markers.size();
    found += solved.markersFound;
    const PoseError error = poseError(solved.calibration.pose, camera.pose);
    EXPECT_LT(error.positionCm, 1.0);
    EXPECT_LT(error.rotationDeg, 0.2);
    EXPECT_LT(solved.calibration.rmsPx, 0.3);
    worstCm = std::max(worstCm, error.positionCm);
    worstDeg = std::max(worstDeg, error.rotationDeg);
    worstRms = std::max(worstRms, solved.calibration.rmsPx);
  }
  ::testing::Test::RecordProperty("markers_found", fmt::format("{} of {}", found, placed));
  ::testing::Test::RecordProperty("worst_position_cm", std::to_string(worstCm));
  ::testing::Test::RecordProperty("worst_rotation_deg", std::to_string(worstDeg));
  ::testing::Test::RecordProperty("worst_rms_px", std::to_string(worstRms));
}

TEST(ExtrinsicCalibration, EveryCameraOfThePinholeRigFromBoardsAndArucoMarkers) {
  expectEveryCameraPosed("paper.yaml", kGroundViewSize, groundMarkers(0.2, 0.4));
}

TEST(ExtrinsicCalibration, EveryCameraOfTheFisheyeRigFromBoardsAndArucoMarkers) {
  expectEveryCameraPosed("fisheye.yaml", kGroundViewSize, groundMarkers(0.12, 0.25));
}

// Listed points (surveyed poles, wall corners) over the whole fisheye field, half of them in the
// crescents at the image's left and right edges that lie past 90 degrees off axis, with detection
// noise and two gross mistakes: the mistakes are found and left out, the pose is still right.
TEST(ExtrinsicCalibration, ListedPointsPastNinetyDegreesWithOutliers) {
  const auto camera = presetCameras("fisheye.yaml")[1];  // right: mirror height, steeply down
  const processing::CameraModel model(camera.intrinsics);
  const auto& lens = camera.intrinsics;
  synth::HashRng rng(5, 0);
  std::vector<processing::PointCorrespondence> points;
  int pastNinety = 0;
  while (points.size() < 40) {
    const bool edge = points.size() % 2 == 1;
    // One draw per statement, in the order x86-64 builds drew them (tools/synth/hash.hpp).
    const double jitter = rng.uniform(-0.5, 0.5);
    const double angle = jitter + (rng.uniform(0, 1) < 0.5 ? 0 : std::numbers::pi);
    const double radius = rng.uniform(0.95, 1.0) * lens.imageSize.width / 2;
    cv::Point2d pixel(lens.cx + radius * std::cos(angle), lens.cy + radius * std::sin(angle));
    if (!edge) {
      pixel.y = rng.uniform(0, lens.imageSize.height - 1);
      pixel.x = rng.uniform(0, lens.imageSize.width - 1);
    }
    const auto ray = model.unproject(pixel);
    if (!ray || !model.inImage(pixel)) continue;
    pastNinety += (*ray)[2] < 0 ? 1 : 0;
    const cv::Vec3d vehicle = camera.pose.toVehicle(*ray * rng.uniform(1, 6));
    const double noiseY = rng.uniform(-0.15, 0.15);
    const double noiseX = rng.uniform(-0.15, 0.15);
    const cv::Point2d noise(noiseX, noiseY);
    points.push_back({vehicle, pixel + noise, "point " + std::to_string(points.size())});
  }
  points[3].pixel += cv::Point2d(25, -10);
  points[17].vehicle += cv::Vec3d(0.5, 0, 0);
  ASSERT_GE(pastNinety, 5);

  const auto result = processing::calibrateExtrinsics(camera.intrinsics, points);
  EXPECT_FALSE(result.inlier[3]);
  EXPECT_FALSE(result.inlier[17]);
  EXPECT_EQ(result.inlierCount, 38);
  const PoseError error = poseError(result.pose, camera.pose);
  EXPECT_LT(error.positionCm, 1.0);
  EXPECT_LT(error.rotationDeg, 0.2);
  RecordProperty("points_past_90_deg", pastNinety);
  RecordProperty("position_cm", std::to_string(error.positionCm));
  RecordProperty("rotation_deg", std::to_string(error.rotationDeg));
}

TEST(ExtrinsicCalibration, TooFewPointsAndPixelsOutsideTheLensAreNamed) {
  const auto camera = presetCameras("fisheye.yaml").front();
  std::vector<processing::PointCorrespondence> points(5, {{1, 0, 0}, {320, 180}, "p"});
  const auto solve = [&] { processing::calibrateExtrinsics(camera.intrinsics, points); };
  expectCalibrationError(
      solve, "too few points: 5 marker corners or listed points, at least 6 are needed");
  points.resize(8, points.front());
  points[6] = {{1, 0, 0}, {2, 2}, "point 'corner_of_the_sensor'"};
  expectCalibrationError(
      solve, "point 'corner_of_the_sensor': pixel (2.0, 2.0) is outside the lens's field");
}

}  // namespace
}  // namespace surroundd::calibration::testing
