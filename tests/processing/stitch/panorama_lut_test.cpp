// The panorama LUT on the paper rig: who owns which azimuths, where the seams and their blend
// bands are, what happens where no camera sees, and a camera that sees nothing. The stitcher
// against a floating-point evaluation of the same geometry, and on any number of threads.

#include "processing/stitch/panorama_lut.hpp"

#include <cmath>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/work_pool.hpp"
#include "processing/stitch/stitcher.hpp"
#include "tests/processing/panorama_test_support.hpp"

namespace surroundd::processing {
namespace {

using testing::settingsFor;
using testing::smallRecording;
using testing::truthImages;

constexpr double kPi = std::numbers::pi;

int cameraIndex(const Rig& rig, const std::string& name) {
  for (std::size_t i = 0; i < rig.cameras.size(); ++i) {
    if (rig.cameras[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

// Bilinear sample in double precision, pixel centres at integer coordinates.
cv::Vec3d sampleExact(const cv::Mat& image, const cv::Point2d& p) {
  const int x0 = std::min(static_cast<int>(std::floor(p.x)), image.cols - 2);
  const int y0 = std::min(static_cast<int>(std::floor(p.y)), image.rows - 2);
  const double fx = p.x - x0;
  const double fy = p.y - y0;
  const auto at = [&](int y, int x) { return cv::Vec3d(image.at<cv::Vec3b>(y, x)); };
  return (1 - fy) * ((1 - fx) * at(y0, x0) + fx * at(y0, x0 + 1)) +
         fy * ((1 - fx) * at(y0 + 1, x0) + fx * at(y0 + 1, x0 + 1));
}

class PanoramaLutTest : public ::testing::Test {
 protected:
  WorkPool pool_{2};
  const bench::RecordingTruth& truth_ = smallRecording();
  PanoramaSettings settings_ = settingsFor(truth_);
  PanoramaLut lut_ = buildPanoramaLut(truth_.rig, settings_, pool_);
};

TEST_F(PanoramaLutTest, EachCameraOwnsTheSectorAroundItsAxis) {
  const auto& geometry = settings_.geometry;
  const cv::Mat owner = lut_.ownerMap();
  const int groundRow = static_cast<int>(geometry.row(-35 * kPi / 180));
  for (const auto& [name, azimuthDeg] : {std::pair{"front", 0.0}, std::pair{"left", 90.0},
                                         std::pair{"back", 179.0}, std::pair{"right", -90.0}}) {
    for (const double offset : {-40.0, 0.0, 40.0}) {
      const double column = geometry.column((azimuthDeg + offset) * kPi / 180);
      EXPECT_EQ(owner.at<std::uint8_t>(groundRow, static_cast<int>(std::lround(column))),
                cameraIndex(truth_.rig, name))
          << name << " at " << azimuthDeg + offset << " deg";
    }
  }
}

TEST_F(PanoramaLutTest, BlendBandsSitOnTheBisectorsWithAFeatherOfTheConfiguredWidth) {
  const auto& geometry = settings_.geometry;
  ASSERT_FALSE(lut_.blendTaps.empty());
  std::vector<int> perSeam(4, 0);
  for (const auto& blend : lut_.blendTaps) {
    const double azimuthDeg = geometry.azimuth(blend.pixel % lut_.size.width) * 180 / kPi;
    // Distance to the nearest of the seams at +-45 and +-135 degrees.
    const double toSeam = std::abs(std::remainder(azimuthDeg - 45, 90.0));
    EXPECT_LE(toSeam, settings_.featherRad * 180 / kPi / 2 + 1e-9);
    EXPECT_GE(blend.tap.weight, 1);
    EXPECT_LE(blend.tap.weight, 128);  // the neighbour never outweighs the owner
    EXPECT_NE(blend.tap.camera, lut_.taps[blend.pixel].camera);
    ++perSeam[static_cast<std::size_t>(std::floor((azimuthDeg + 180) / 90)) % 4];
  }
  for (const int count : perSeam) EXPECT_GT(count, 100);
  // Rows index the blend taps.
  for (int v = 0; v < lut_.size.height; ++v) {
    for (auto b = lut_.blendRowBegin[v]; b < lut_.blendRowBegin[v + 1]; ++b) {
      ASSERT_EQ(lut_.blendTaps[b].pixel / lut_.size.width, static_cast<std::uint32_t>(v));
    }
  }
}

TEST_F(PanoramaLutTest, PixelsNoCameraSeesAreMaskedAndHaveTheUnseenColour) {
  // The paper's cameras see down to about -58 degrees and up to about +8: the top rows and the
  // bottom corners between cameras are seen by none.
  const cv::Mat mask = lut_.validMask();
  EXPECT_EQ(cv::countNonZero(mask.row(0)), 0);
  EXPECT_EQ(cv::countNonZero(mask.row(lut_.size.height * 3 / 4)), lut_.size.width);
  const double seen = cv::countNonZero(mask) / static_cast<double>(lut_.size.area());
  EXPECT_GT(seen, 0.6);
  EXPECT_LT(seen, 0.9);

  Stitcher stitcher(lut_, pool_);
  cv::Mat panorama;
  stitcher.stitch(truthImages(truth_.frames.front()), panorama);
  cv::Mat unseen;
  cv::inRange(panorama, cv::Scalar(PanoramaLut::kUnseenColour),
              cv::Scalar(PanoramaLut::kUnseenColour), unseen);
  EXPECT_EQ(cv::countNonZero(unseen & ~mask), cv::countNonZero(~mask));
}

TEST_F(PanoramaLutTest, StitcherMatchesFloatingPointBilinearAndBlend) {
  const auto images = truthImages(truth_.frames.front());
  Stitcher stitcher(lut_, pool_);
  cv::Mat panorama;
  stitcher.stitch(images, panorama);

  const PanoramaProjector projector(truth_.rig, settings_);
  std::vector<double> blendWeight(static_cast<std::size_t>(lut_.size.area()), 0);
  std::vector<int> blendCamera(blendWeight.size(), -1);
  for (const auto& blend : lut_.blendTaps) {
    blendWeight[blend.pixel] = blend.tap.weight / 256.0;
    blendCamera[blend.pixel] = blend.tap.camera;
  }
  double worst = 0;
  double sum = 0;
  int count = 0;
  for (int v = 0; v < lut_.size.height; ++v) {
    for (int u = 0; u < lut_.size.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * lut_.size.width + u;
      const int camera = lut_.taps[i].camera;
      if (camera == PanoramaLut::kUnseen) continue;
      const cv::Point2d pixel(u, v);
      cv::Vec3d expected = sampleExact(images[camera], *projector.cameraPixel(camera, pixel));
      if (blendCamera[i] >= 0) {
        const cv::Vec3d other =
            sampleExact(images[blendCamera[i]], *projector.cameraPixel(blendCamera[i], pixel));
        expected = (1 - blendWeight[i]) * expected + blendWeight[i] * other;
      }
      const cv::Vec3d got(panorama.at<cv::Vec3b>(v, u));
      for (int c = 0; c < 3; ++c) {
        const double difference = std::abs(got[c] - expected[c]);
        worst = std::max(worst, difference);
        sum += difference;
        ++count;
      }
    }
  }
  // Fixed point: positions in 1/128 pixel, weights in 1/128 and 1/256, two roundings.
  EXPECT_LE(worst, 2.0);
  EXPECT_LT(sum / count, 0.3);
}

TEST_F(PanoramaLutTest, StitchingIsTheSameOnAnyNumberOfThreads) {
  const auto images = truthImages(truth_.frames.back());
  WorkPool one(1);
  WorkPool three(3);
  Stitcher single(lut_, one);
  Stitcher parallel(lut_, three);
  cv::Mat a;
  cv::Mat b;
  single.stitch(images, a);
  parallel.stitch(images, b);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0);
  // And again into the same buffer: stitching does not reallocate it.
  const auto* data = b.data;
  parallel.stitch(images, b);
  EXPECT_EQ(b.data, data);
}

TEST_F(PanoramaLutTest, RejectsFramesThatDoNotMatchTheLut) {
  Stitcher stitcher(lut_, pool_);
  auto images = truthImages(truth_.frames.front());
  cv::Mat panorama;
  images.pop_back();
  EXPECT_THAT([&] { stitcher.stitch(images, panorama); },
              ::testing::ThrowsMessage<std::invalid_argument>(::testing::HasSubstr("3 frames")));
  images.emplace_back(10, 10, CV_8UC3);
  EXPECT_THAT([&] { stitcher.stitch(images, panorama); },
              ::testing::ThrowsMessage<std::invalid_argument>(::testing::HasSubstr("frame 3")));
}

TEST(PanoramaLut, ACameraThatSeesNothingIsNamed) {
  Rig rig = smallRecording().rig;
  rig.cameras[2].pose.rotation = rotationFromMountAngles({180, 89, 0});  // 'back' looks at the sky
  WorkPool pool(1);
  EXPECT_THAT([&] { buildPanoramaLut(rig, settingsFor(smallRecording()), pool); },
              ::testing::ThrowsMessage<RigError>(
                  ::testing::HasSubstr("camera 'back' contributes nothing to the panorama")));
}

// A camera that sees only its own car (its body mask hides all it would show: a camera inside
// the body's box) is no rig error: the LUT takes nothing from it and names it, the other cameras
// make the panorama as they would beside it.
TEST(PanoramaLut, ACameraHiddenByTheBodyGivesNothingAndTheOthersGoOn) {
  Rig rig = smallRecording().rig;
  const cv::Size size = rig.cameras[2].intrinsics.imageSize;
  rig.cameras[2].bodyMask = cv::Mat(size, CV_8U, cv::Scalar(255));
  WorkPool pool(1);
  const PanoramaLut lut = buildPanoramaLut(rig, settingsFor(smallRecording()), pool);
  EXPECT_EQ(lut.camerasWithoutTaps(), std::vector<std::size_t>{2});
  const PanoramaLut whole =
      buildPanoramaLut(smallRecording().rig, settingsFor(smallRecording()), pool);
  EXPECT_TRUE(whole.camerasWithoutTaps().empty());
  // Where the back camera was the only one to see the ground, nothing does now; elsewhere the
  // others' taps are those of the whole rig.
  std::size_t same = 0, lost = 0;
  for (std::size_t i = 0; i < lut.taps.size(); ++i) {
    if (whole.taps[i].camera == 2) {
      lost += lut.taps[i].camera == PanoramaLut::kUnseen ? 1 : 0;
    } else {
      same += lut.taps[i].camera == whole.taps[i].camera ? 1 : 0;
    }
  }
  EXPECT_GT(lost, 0U);
  EXPECT_GT(same, lut.taps.size() / 2);
}

TEST(PanoramaLut, ProgressIsReportedUpToTheEnd) {
  WorkPool pool(2);
  std::vector<double> reports;
  buildPanoramaLut(smallRecording().rig, settingsFor(smallRecording()), pool,
                   [&](double done) { reports.push_back(done); });
  ASSERT_FALSE(reports.empty());
  EXPECT_TRUE(std::ranges::is_sorted(reports));
  EXPECT_DOUBLE_EQ(reports.back(), 1.0);
}

}  // namespace
}  // namespace surroundd::processing
