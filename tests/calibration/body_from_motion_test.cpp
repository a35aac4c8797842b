// The body found from a drive (processing/calibration/body_from_motion.hpp) against the generator's
// true body masks, on ten-second drives of two rigs:
// - the paper's roof rig: the roof under each camera, glossy, mirrors the sky (which turns with
//   the car) — found whole (intersection over union >= 0.95), almost no ground masked;
// - the fisheye rig, cameras in the bumpers and under the mirrors, crates close by: the body's
//   paint mirrors the road at the grazing angles those cameras see it, so only the part with a
//   still picture is found; what is found is body (>= 95 %), and added to the mask computed from
//   the vehicle (mode: add) it leaves that mask's fit as it was.
// And a car that did not move says so (movingShare()), where its mask would mean nothing.

#include "processing/calibration/body_from_motion.hpp"

#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "tests/support/test_support.hpp"
#include "tools/bench/recording_truth.hpp"

namespace surroundd::processing {
namespace {

struct Overlap {
  double iou = 0;
  double precision = 0;          // of what was found: body
  double groundMaskedShare = 0;  // of the true ground: masked by mistake
};

Overlap overlap(const cv::Mat& found, const cv::Mat& truth) {
  const double both = cv::countNonZero(found & truth);
  const double either = cv::countNonZero(found | truth);
  const double all = cv::countNonZero(found);
  const double ground = static_cast<double>(truth.total()) - cv::countNonZero(truth);
  return {either > 0 ? both / either : 1, all > 0 ? both / all : 1,
          cv::countNonZero(found & ~truth) / ground};
}

struct CameraResult {
  std::string name;
  Overlap found;
  Overlap withComputed;  // the found body added to the mask computed from the rig's vehicle
  double movingShare = 0;
};

std::vector<CameraResult> findBodies(const std::string& fixture) {
  const auto folder = std::filesystem::path(SURROUNDD_FIXTURE_DIR) / fixture;
  const bench::RecordingTruth truth = bench::loadRecordingTruth(folder);
  const YAML::Node groundTruth = YAML::LoadFile((folder / "ground_truth.yaml").string());
  std::vector<CameraResult> results;
  for (std::size_t c = 0; c < truth.rig.cameras.size(); ++c) {
    const CameraCalibration& camera = truth.rig.cameras[c];
    const cv::Mat trueBody =
        cv::imread((folder / groundTruth["cameras"][c]["body_mask"].as<std::string>()).string(),
                   cv::IMREAD_GRAYSCALE) > 0;
    BodyFromMotion finder(camera);
    for (const cv::Mat& picture : testing::decodeAll(folder / (camera.name + ".mkv")).images) {
      finder.add(picture);
    }
    const cv::Mat found = finder.mask();
    const Overlap o = overlap(found, trueBody);
    const Overlap u = overlap(found | (camera.bodyMask > 0), trueBody);
    std::printf(
        "%s %s: found IoU %.3f (%.3f of it body, %.4f of the ground masked); with the "
        "computed mask IoU %.3f; %.0f %% moved\n",
        fixture.c_str(), camera.name.c_str(), o.iou, o.precision, o.groundMaskedShare, u.iou,
        100 * finder.movingShare());
    results.push_back({camera.name, o, u, finder.movingShare()});
  }
  return results;
}

TEST(BodyFromMotion, FindsTheRoofUnderTheRoofCamerasWhole) {
  for (const CameraResult& camera : findBodies("synth_drive_paper")) {
    EXPECT_GE(camera.found.iou, 0.95) << camera.name;
    EXPECT_LT(camera.found.groundMaskedShare, 0.01) << camera.name;
    EXPECT_GT(camera.movingShare, 0.5) << camera.name;
  }
}

TEST(BodyFromMotion, FindsOnlyBodyWhereThePaintMirrorsTheRoad) {
  for (const CameraResult& camera : findBodies("synth_drive_fisheye")) {
    EXPECT_GE(camera.found.precision, 0.95) << camera.name;
    EXPECT_GT(camera.found.iou, 0.02) << camera.name << ": something of the body is found";
    EXPECT_LT(camera.found.groundMaskedShare, 0.005) << camera.name;
    EXPECT_GE(camera.withComputed.iou, 0.95) << camera.name;
  }
}

TEST(BodyFromMotion, ACarThatStoodStillMovedNothing) {
  const auto folder = std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_drive_paper";
  const bench::RecordingTruth truth = bench::loadRecordingTruth(folder);
  const cv::Mat picture = testing::decodeAll(folder / "front.mkv", false, 1).images.at(0);
  BodyFromMotion finder(truth.rig.cameras.front());
  for (int i = 0; i < 12; ++i) finder.add(picture);
  EXPECT_EQ(finder.pairs(), 12 - BodyFromMotionSettings{}.span);
  EXPECT_LT(finder.movingShare(), 0.01);
  EXPECT_THROW(finder.add(cv::Mat(10, 10, CV_8UC3)), std::invalid_argument);
}

TEST(BodyFromMotion, OutlinesArePolygonsAroundEachRegion) {
  cv::Mat mask(100, 200, CV_8U, cv::Scalar(0));
  cv::rectangle(mask, cv::Rect(0, 70, 200, 30), cv::Scalar(255), cv::FILLED);  // a bumper
  cv::circle(mask, {20, 20}, 10, cv::Scalar(255), cv::FILLED);                 // a mirror
  const auto polygons = maskOutlines(mask, 1.0);
  ASSERT_EQ(polygons.size(), 2U);
  cv::Mat drawn(mask.size(), CV_8U, cv::Scalar(0));
  for (const auto& polygon : polygons) {
    cv::fillPoly(drawn, std::vector{polygon}, cv::Scalar(255));
  }
  EXPECT_GE(overlap(drawn, mask).iou, 0.97);
  // The rectangle is four corners, not its hundreds of outline pixels.
  const auto& bumper = polygons[0].size() < polygons[1].size() ? polygons[0] : polygons[1];
  EXPECT_EQ(bumper.size(), 4U);
}

}  // namespace
}  // namespace surroundd::processing
