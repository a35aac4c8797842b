// The stitched panorama against the generator's ground truth. With the bowl projection, ground
// points meet across every seam (each camera's sample, cast back onto the true ground, lands on
// the same panorama pixel) and the panorama matches the true one over the ground; the paper's
// sphere projection misses by the parallax of cameras 0.3 m from the centre, and the check sees it.

#include "tools/bench/panorama_accuracy.hpp"

#include <gtest/gtest.h>

#include "common/work_pool.hpp"
#include "processing/stitch/stitcher.hpp"
#include "tests/processing/panorama_test_support.hpp"

namespace surroundd::processing {
namespace {

using testing::settingsFor;
using testing::smallRecording;
using testing::truthImages;

TEST(PanoramaAccuracy, BowlSeamsMeetOnTheGroundAndSphereSeamsDoNot) {
  WorkPool pool(2);
  const auto& truth = smallRecording();
  const auto bowl = settingsFor(truth, PanoramaProjection::kBowl);
  const auto sphere = settingsFor(truth, PanoramaProjection::kSphere);
  const auto bowlSeams =
      bench::measureGroundSeams(truth.rig, bowl, buildPanoramaLut(truth.rig, bowl, pool));
  const auto sphereSeams =
      bench::measureGroundSeams(truth.rig, sphere, buildPanoramaLut(truth.rig, sphere, pool));
  EXPECT_GT(bowlSeams.samples, 500);
  EXPECT_LT(bowlSeams.maxPx, 0.01);
  EXPECT_GT(sphereSeams.samples, 500);
  EXPECT_GT(sphereSeams.meanPx, 3.0);
}

TEST(PanoramaAccuracy, BowlPanoramaMatchesTheTrueOneOverTheGround) {
  WorkPool pool(2);
  const auto& truth = smallRecording();
  const synth::Scene scene(truth.seed, truth.seconds);
  for (const auto projection : {PanoramaProjection::kBowl, PanoramaProjection::kSphere}) {
    const auto settings = settingsFor(truth, projection);
    const PanoramaLut lut = buildPanoramaLut(truth.rig, settings, pool);
    Stitcher stitcher(lut, pool);
    for (const auto& frame : truth.frames) {
      cv::Mat panorama;
      stitcher.stitch(truthImages(frame), panorama);
      const cv::Mat ground = bench::trueGroundMask(scene, frame.pose, settings) & lut.validMask();
      ASSERT_GT(cv::countNonZero(ground), lut.size.area() / 5);
      const double error =
          bench::meanAbsoluteError(panorama, cv::imread(frame.panorama.string()), ground);
      if (projection == PanoramaProjection::kBowl) {
        EXPECT_LT(error, 3.0) << "frame " << frame.frame;
      } else {
        EXPECT_GT(error, 4.0) << "frame " << frame.frame;
      }
    }
  }
}

}  // namespace
}  // namespace surroundd::processing
