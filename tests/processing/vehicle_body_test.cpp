// The ego vehicle's body: which rays it blocks, the body masks computed from it for each camera of
// the paper's rig (roof cameras see the roof at the bottom of their pictures), the panorama LUT
// that never samples a masked pixel but takes that ground from a camera that sees it, and on the
// generator's recordings with a rendered body, never a pixel of the true body.

#include "processing/vehicle_body.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "common/work_pool.hpp"
#include "processing/stitch/panorama_lut.hpp"
#include "tests/processing/panorama_test_support.hpp"

namespace surroundd::processing {
namespace {

TEST(VehicleBody, BlocksRaysThatEnterItPastTheLens) {
  const VehicleBody car = boxBody(4.0, 2.0, 1.5, 0.2);
  // From outside: into the body, over it, under it, beside it.
  EXPECT_TRUE(car.blocks({5, 0, 1}, {-1, 0, 0}));
  EXPECT_FALSE(car.blocks({5, 0, 1}, {1, 0, 0}));
  EXPECT_FALSE(car.blocks({5, 0, 2}, {-1, 0, 0}));
  EXPECT_FALSE(car.blocks({5, 0, 0.1}, {-1, 0, 0}));
  EXPECT_FALSE(car.blocks({5, 1.5, 1}, {-1, 0, 0}));
  // A roof camera: the roof below it is body, the ground beyond the roof's edge is not.
  EXPECT_TRUE(car.blocks({0, 0, 1.9}, cv::normalize(cv::Vec3d(1, 0, -1))));
  EXPECT_FALSE(car.blocks({0, 0, 1.9}, cv::normalize(cv::Vec3d(10, 0, -1))));
  // A camera on the front face looks out through it, and sees the bumper below it.
  EXPECT_FALSE(car.blocks({2.0, 0, 0.8}, cv::normalize(cv::Vec3d(1, 0, -0.3))));
  EXPECT_TRUE(car.blocks({2.0, 0, 0.8}, cv::normalize(cv::Vec3d(-0.2, 0, -1))));
  // A little inside the face (a calibration that puts it there) changes nothing.
  EXPECT_FALSE(car.blocks({1.95, 0, 0.8}, cv::normalize(cv::Vec3d(1, 0, -0.3))));
  // Concave footprints (an L) work by the even-odd rule.
  const VehicleBody l{{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}, 0, 1};
  EXPECT_FALSE(l.blocks({1.5, 1.5, 0.5}, {0, 0, -1}));
  EXPECT_TRUE(l.blocks({3, 0.5, 0.5}, {-1, 0, 0}));
  EXPECT_TRUE(l.blocks({3, 1.5, 0.5}, {-1, 0, 0}));  // enters the upper arm at x = 1
}

class BodyMaskTest : public ::testing::Test {
 protected:
  BodyMaskTest()
      : truth_(bench::loadRecordingTruth(std::filesystem::path(SURROUNDD_FIXTURE_DIR) /
                                         "synth_small")),
        settings_(testing::settingsFor(truth_)) {}

  WorkPool pool_{2};
  bench::RecordingTruth truth_;
  PanoramaSettings settings_;
};

TEST_F(BodyMaskTest, RoofCamerasSeeTheRoofAtTheBottomOfTheirPictures) {
  // The paper's rig: cameras at 1.9 m, 0.3 m from the centre, pitched 25 degrees down.
  const VehicleBody car = boxBody(4.5, 1.85, 1.5, 0.15);
  for (const auto& camera : truth_.rig.cameras) {
    const cv::Mat mask = computeBodyMask(car, camera, pool_);
    ASSERT_EQ(mask.size(), camera.intrinsics.imageSize);
    const int rows = mask.rows;
    // The bottom row sees the roof, the top row over it.
    EXPECT_EQ(mask.at<std::uint8_t>(rows - 1, mask.cols / 2), 255) << camera.name;
    EXPECT_EQ(cv::countNonZero(mask.row(0)), 0) << camera.name;
    // Down the middle column, exactly where the ray meets the roof's plane inside its edges (the
    // cameras are 0.4 m above it, so nothing else of the body is in view).
    const CameraModel model(camera.intrinsics);
    for (int v = 0; v < rows; ++v) {
      const auto ray = model.unproject({mask.cols / 2.0, static_cast<double>(v)});
      ASSERT_TRUE(ray.has_value());
      const cv::Vec3d d = camera.pose.rotation * *ray;
      const cv::Vec3d roof = camera.pose.position + d * ((1.5 - camera.pose.position[2]) / d[2]);
      const bool onRoof = d[2] < 0 && std::abs(roof[0]) < 2.25 && std::abs(roof[1]) < 0.925;
      EXPECT_EQ(mask.at<std::uint8_t>(v, mask.cols / 2) != 0, onRoof)
          << camera.name << " row " << v;
    }
  }
}

TEST_F(BodyMaskTest, TheLutNeverSamplesTheBodyAndTakesThatGroundFromAnotherCamera) {
  // A tall van: the roof cameras see its roof over a third of their pictures' height.
  const VehicleBody van = boxBody(4.5, 1.85, 1.7, 0.15);
  Rig masked = truth_.rig;
  for (auto& camera : masked.cameras) camera.bodyMask = computeBodyMask(van, camera, pool_);
  const PanoramaLut plain = buildPanoramaLut(truth_.rig, settings_, pool_);
  const PanoramaLut lut = buildPanoramaLut(masked, settings_, pool_);
  const auto touchesBody = [&](const LutTap& tap) {
    const cv::Mat& mask = masked.cameras[tap.camera].bodyMask;
    const int x = static_cast<int>(tap.offset % static_cast<std::uint32_t>(mask.cols));
    const int y = static_cast<int>(tap.offset / static_cast<std::uint32_t>(mask.cols));
    return cv::countNonZero(mask(cv::Rect(x, y, 2, 2))) > 0;
  };
  int moved = 0, lost = 0;
  for (std::size_t i = 0; i < lut.taps.size(); ++i) {
    const LutTap& tap = lut.taps[i];
    if (tap.camera != PanoramaLut::kUnseen) {
      ASSERT_FALSE(touchesBody(tap)) << "pixel " << i;
    }
    if (plain.taps[i].camera != PanoramaLut::kUnseen && touchesBody(plain.taps[i])) {
      (tap.camera == PanoramaLut::kUnseen ? lost : moved) += 1;
    }
  }
  for (const auto& blend : lut.blendTaps) ASSERT_FALSE(touchesBody(blend.tap));
  // Ground a camera's roof hid from it, that a neighbour sees past the roof, comes from the
  // neighbour; right under the body no camera sees the ground.
  EXPECT_GT(moved, 0);
  EXPECT_GT(lost, 0);
}

// The generator's own body (rounded, its roof a mirror of the scene) and its true masks: the
// panorama stitched with the masks computed from the rig's vehicle never samples a pixel of the
// body.
class TrueBodyTest : public ::testing::TestWithParam<const char*> {};

TEST_P(TrueBodyTest, StitchedGroundNeverComesFromTheBody) {
  const auto folder = std::filesystem::path(SURROUNDD_FIXTURE_DIR) / GetParam();
  const bench::RecordingTruth truth = bench::loadRecordingTruth(folder);
  const YAML::Node groundTruth = YAML::LoadFile((folder / "ground_truth.yaml").string());
  std::vector<cv::Mat> bodies;
  for (const auto& camera : truth.rig.cameras) {
    ASSERT_FALSE(camera.bodyMask.empty()) << camera.name << ": the recording's vehicle is masked";
    for (const auto& entry : groundTruth["cameras"]) {
      if (entry["name"].as<std::string>() == camera.name) {
        bodies.push_back(cv::imread((folder / entry["body_mask"].as<std::string>()).string(),
                                    cv::IMREAD_GRAYSCALE));
      }
    }
    ASSERT_EQ(bodies.size(), &camera - truth.rig.cameras.data() + 1) << camera.name;
    ASSERT_GT(cv::countNonZero(bodies.back()), 0) << camera.name << " sees the body";
  }
  WorkPool pool(2);
  const PanoramaSettings settings = testing::settingsFor(truth);
  const PanoramaLut lut = buildPanoramaLut(truth.rig, settings, pool);
  const auto onBody = [&](const LutTap& tap) {
    const cv::Mat& body = bodies[tap.camera];
    const int x = static_cast<int>(tap.offset % static_cast<std::uint32_t>(body.cols));
    const int y = static_cast<int>(tap.offset / static_cast<std::uint32_t>(body.cols));
    return cv::countNonZero(body(cv::Rect(x, y, 2, 2))) > 0;
  };
  std::size_t seen = 0;
  for (const auto& tap : lut.taps) {
    if (tap.camera == PanoramaLut::kUnseen) continue;
    ++seen;
    ASSERT_FALSE(onBody(tap)) << truth.rig.cameras[tap.camera].name;
  }
  for (const auto& blend : lut.blendTaps) ASSERT_FALSE(onBody(blend.tap));
  EXPECT_GT(seen, lut.taps.size() / 3);  // and the ground around the body is there
}

INSTANTIATE_TEST_SUITE_P(GeneratedBodies, TrueBodyTest,
                         ::testing::Values("synth_body_paper", "synth_body_fisheye"));

}  // namespace
}  // namespace surroundd::processing
