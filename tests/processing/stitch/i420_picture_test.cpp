// A view's picture converted to I420 for the encoders (issue 19.3): BT.601 limited range, each
// chroma sample from the mean of its 2x2 pixels, as the project's reference conversion
// (common/pixel_format.hpp's bgrToHeld, NV12: the same samples, interleaved) gives them within a
// level of rounding — on a panorama stitched from the synth_small recording's first frame set.

#include "processing/stitch/i420_picture.hpp"

#include <cstdint>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "common/pixel_format.hpp"
#include "common/work_pool.hpp"
#include "processing/stitch/stitcher.hpp"
#include "tests/processing/panorama_test_support.hpp"

namespace surroundd::processing {
namespace {

cv::Mat stitchedPanorama(WorkPool& pool) {
  const auto& truth = testing::smallRecording();
  const PanoramaLut lut = buildPanoramaLut(truth.rig, testing::settingsFor(truth), pool);
  Stitcher stitcher(lut, pool);
  cv::Mat panorama;
  stitcher.stitch(testing::truthImages(truth.frames.at(0)), panorama);
  return panorama;
}

TEST(I420Picture, IsTheReferenceConversionWithinALevel) {
  WorkPool pool(2);
  // 510 columns: the vector path's 16 at a time and the blocks left over.
  const cv::Mat panorama = stitchedPanorama(pool)(cv::Rect(1, 0, 510, 256));
  cv::Mat i420;
  bgrToI420(panorama, i420, pool);
  ASSERT_EQ(i420.size(), cv::Size(510, 384));
  cv::Mat nv12;
  bgrToHeld(panorama.clone(), PixelFormat::kNv12, nv12);
  const cv::Mat luma = i420.rowRange(0, 256);
  EXPECT_LE(cv::norm(luma, nv12.rowRange(0, 256), cv::NORM_INF), 1.0);
  // NV12's Cb Cr pairs against I420's two planes.
  const cv::Mat pairs = nv12.rowRange(256, 384).clone().reshape(2, 128);
  std::vector<cv::Mat> chroma;
  cv::split(pairs, chroma);
  const std::uint8_t* cbPlane = i420.ptr<std::uint8_t>(256);
  const cv::Mat cb(128, 255, CV_8UC1, const_cast<std::uint8_t*>(cbPlane));
  const cv::Mat cr(128, 255, CV_8UC1,
                   const_cast<std::uint8_t*>(cbPlane + std::ptrdiff_t{128} * 255));
  EXPECT_LE(cv::norm(cb, chroma[0], cv::NORM_INF), 1.0);
  EXPECT_LE(cv::norm(cr, chroma[1], cv::NORM_INF), 1.0);
  // Not a flat picture: the comparison means something.
  cv::Scalar mean, deviation;
  cv::meanStdDev(cb, mean, deviation);
  EXPECT_GT(deviation[0], 2.0);
}

TEST(I420Picture, DecodesBackToThePictureAsOpenCvReadsI420) {
  WorkPool pool(2);
  const cv::Mat panorama = stitchedPanorama(pool);
  cv::Mat i420;
  bgrToI420(panorama, i420, pool);
  cv::Mat back;
  cv::cvtColor(i420, back, cv::COLOR_YUV2BGR_I420);
  // Chroma at half resolution costs the sharp edges a few levels; the picture stays.
  EXPECT_GT(cv::PSNR(back, panorama), 30.0);
}

TEST(I420Picture, RefusesWhatIsNotBgrOfEvenSides) {
  WorkPool pool(1);
  cv::Mat i420;
  EXPECT_THROW(bgrToI420(cv::Mat(4, 5, CV_8UC3), i420, pool), std::invalid_argument);
  EXPECT_THROW(bgrToI420(cv::Mat(3, 4, CV_8UC3), i420, pool), std::invalid_argument);
  EXPECT_THROW(bgrToI420(cv::Mat(4, 4, CV_8UC1), i420, pool), std::invalid_argument);
}

}  // namespace
}  // namespace surroundd::processing
