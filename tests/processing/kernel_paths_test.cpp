// Every kernel path a build has (processing/stitch/kernel_path.hpp: SSE2 on x86-64, NEON on
// arm64) gives exactly the bytes of the portable one (issue 19.4), on the synth_small recording's
// first frame set through its own panorama LUT, its frames held as BGR, YUYV and NV12 as cameras
// deliver them (issue 19.3): every tap of the LUT and of its seam blends sampled alone, the whole
// stitch, the colour correction's fields applied to it, its conversion to I420, and every pair of
// weights on pictures of random and extreme bytes.

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <span>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "common/work_pool.hpp"
#include "processing/colour/poisson_correction.hpp"
#include "processing/stitch/bilinear_sample.hpp"
#include "processing/stitch/i420_picture.hpp"
#include "processing/stitch/kernel_path.hpp"
#include "processing/stitch/stitcher.hpp"
#include "tests/processing/panorama_test_support.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::processing {
namespace {

#if defined(__x86_64__)
// Or the comparisons below would compare the portable path with itself.
static_assert(kernelPathBuilt(KernelPath::kSse2));
#elif defined(__aarch64__)
static_assert(kernelPathBuilt(KernelPath::kNeon));
#endif

class KernelPathsTest : public ::testing::Test {
 protected:
  KernelPathsTest()
      : truth_(testing::smallRecording()),
        lut_(buildPanoramaLut(truth_.rig, testing::settingsFor(truth_), pool_)) {
    for (const auto& video : truth_.videos) {
      frames_.push_back(surroundd::testing::decodeAll(video, false, 1).images.at(0));
    }
    for (const PixelFormat format : kFormats) {
      auto& held = held_[static_cast<std::size_t>(format)];
      for (const cv::Mat& frame : frames_) bgrToHeld(frame, format, held.emplace_back());
    }
  }
  const std::vector<cv::Mat>& held(PixelFormat format) const {
    return held_[static_cast<std::size_t>(format)];
  }
  // For both fields: a correction fitted to the frames, applied to `picture` by `correct` on each
  // path, gives the portable path's bytes, and changes the picture.
  void expectEveryPathCorrectsAlike(
      const cv::Mat& picture,
      const std::function<void(PoissonColourCorrection&, cv::Mat&, KernelPath)>& correct) {
    for (const CorrectionField field :
         {CorrectionField::kMultiplicative, CorrectionField::kAdditive}) {
      SCOPED_TRACE(correctionFieldName(field));
      ColourCorrectionSettings correction;
      correction.field = field;
      PoissonColourCorrection poisson(truth_.rig, testing::settingsFor(truth_), lut_, correction,
                                      pool_);
      poisson.update(frames_);
      cv::Mat portable = picture.clone();
      correct(poisson, portable, KernelPath::kPortable);
      ASSERT_GT(cv::norm(portable, picture, cv::NORM_L1), 1000.0);  // a field that changes it
      for (const KernelPath path : kKernelPaths) {
        SCOPED_TRACE(kernelPathName(path));
        cv::Mat corrected = picture.clone();
        correct(poisson, corrected, path);
        EXPECT_EQ(cv::norm(corrected, portable, cv::NORM_INF), 0.0);
      }
    }
  }

  // The frame set's panorama, resized to a view's picture.
  cv::Mat panoramaResizedTo(cv::Size view) {
    Stitcher stitcher(lut_, pool_);
    cv::Mat raw;
    stitcher.stitch(frames_, raw);
    cv::Mat picture;
    cv::resize(raw, picture, view, 0, 0, cv::INTER_AREA);
    return picture;
  }

  static constexpr std::array kFormats = {PixelFormat::kBgr, PixelFormat::kYuyv, PixelFormat::kUyvy,
                                          PixelFormat::kNv12};
  WorkPool pool_{2};
  const bench::RecordingTruth& truth_;
  PanoramaLut lut_;
  std::vector<cv::Mat> frames_;                           // BGR, as decoded
  std::array<std::vector<cv::Mat>, kPixelFormats> held_;  // per PixelFormat
};

template <KernelPath kPath>
std::uint32_t sampleAs(const SampledImage& image, const LutTap& tap) {
  switch (image.format) {
    case PixelFormat::kYuyv:
      return bilinear<PixelFormat::kYuyv, kPath>(image, tap);
    case PixelFormat::kUyvy:
      return bilinear<PixelFormat::kUyvy, kPath>(image, tap);
    case PixelFormat::kNv12:
      return bilinear<PixelFormat::kNv12, kPath>(image, tap);
    case PixelFormat::kBgr:
      break;
  }
  return bilinear<PixelFormat::kBgr, kPath>(image, tap);
}

// Each seen tap of the LUT, then each blend tap, sampled by path kPath.
template <KernelPath kPath>
std::vector<std::uint32_t> sampleEveryTap(const PanoramaLut& lut, std::span<const cv::Mat> frames,
                                          PixelFormat format) {
  std::vector<std::uint32_t> samples;
  const auto sample = [&](const LutTap& tap) {
    samples.push_back(sampleAs<kPath>(SampledImage::of(frames[tap.camera], format), tap));
  };
  for (const LutTap& tap : lut.taps) {
    if (tap.camera != PanoramaLut::kUnseen) sample(tap);
  }
  for (const BlendTap& blend : lut.blendTaps) sample(blend.tap);
  return samples;
}

template <std::size_t... kIndex>
std::array<std::vector<std::uint32_t>, kKernelPaths.size()> sampleEveryTapByEveryPath(
    const PanoramaLut& lut, std::span<const cv::Mat> frames, PixelFormat format,
    std::index_sequence<kIndex...>) {
  return {sampleEveryTap<kKernelPaths[kIndex]>(lut, frames, format)...};
}

TEST_F(KernelPathsTest, EveryPathSamplesEveryTapOfARealLutAlike) {
  for (const PixelFormat format : kFormats) {
    SCOPED_TRACE(toString(format));
    const auto samples = sampleEveryTapByEveryPath(lut_, held(format), format,
                                                   std::make_index_sequence<kKernelPaths.size()>());
    ASSERT_EQ(kKernelPaths[0], KernelPath::kPortable);
    ASSERT_GT(samples[0].size(), lut_.taps.size() / 2);
    for (std::size_t p = 1; p < kKernelPaths.size(); ++p) {
      SCOPED_TRACE(kernelPathName(kKernelPaths[p]));
      ASSERT_EQ(samples[p].size(), samples[0].size());
      std::size_t differing = 0;
      for (std::size_t i = 0; i < samples[0].size(); ++i) {
        differing += samples[p][i] != samples[0][i] ? 1 : 0;
      }
      EXPECT_EQ(differing, 0u) << "of " << samples[0].size() << " taps";
    }
  }
}

TEST_F(KernelPathsTest, EveryPathStitchesTheSameBytes) {
  Stitcher stitcher(lut_, pool_);
  for (const PixelFormat format : kFormats) {
    SCOPED_TRACE(toString(format));
    cv::Mat portable;
    stitcher.stitch(held(format), format, portable, KernelPath::kPortable);
    for (const KernelPath path : kKernelPaths) {
      SCOPED_TRACE(kernelPathName(path));
      cv::Mat panorama;
      stitcher.stitch(held(format), format, panorama, path);
      ASSERT_EQ(panorama.size(), portable.size());
      EXPECT_EQ(cv::norm(panorama, portable, cv::NORM_INF), 0.0);
    }
    // The native path is the one stitch() takes by default.
    cv::Mat native;
    stitcher.stitch(held(format), format, native);
    EXPECT_EQ(cv::norm(native, portable, cv::NORM_INF), 0.0);
  }
}

// A stitched panorama converted to I420 by each path; 510 columns, so that the vector paths' last
// blocks are done the portable way.
TEST_F(KernelPathsTest, EveryPathConvertsToI420Alike) {
  Stitcher stitcher(lut_, pool_);
  cv::Mat panorama;
  stitcher.stitch(frames_, panorama);
  const cv::Mat picture = panorama(cv::Rect(2, 0, 510, lut_.size.height));
  cv::Mat portable(i420HeldSize(picture.size()), CV_8UC1);
  bgrRowsToI420(picture, 0, picture.rows, portable, KernelPath::kPortable);
  for (const KernelPath path : kKernelPaths) {
    SCOPED_TRACE(kernelPathName(path));
    cv::Mat i420(portable.size(), CV_8UC1, cv::Scalar(0));
    bgrRowsToI420(picture, 0, picture.rows, i420, path);
    EXPECT_EQ(cv::norm(i420, portable, cv::NORM_INF), 0.0);
  }
}

// The colour correction's field applied by each path, both fields, over the whole stitched
// panorama: the blend bands' pixels (a share of the source camera) and the rest.
TEST_F(KernelPathsTest, EveryPathAppliesTheSameCorrection) {
  Stitcher stitcher(lut_, pool_);
  cv::Mat raw;
  stitcher.stitch(frames_, raw);
  expectEveryPathCorrectsAlike(raw, [](PoissonColourCorrection& poisson, cv::Mat& picture,
                                       KernelPath path) { poisson.apply(picture, path); });
}

// Where a 320x200 view samples the panorama of `panorama`'s size: all of it, from sub-pixel
// positions, but for a band that shows none of it.
cv::Mat viewPositions(cv::Size panorama) {
  const cv::Size view(320, 200);
  const float across = static_cast<float>(panorama.width) / static_cast<float>(view.width);
  const float down = static_cast<float>(panorama.height - 1) / static_cast<float>(view.height);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  cv::Mat positions(view, CV_32FC2);
  for (int v = 0; v < view.height; ++v) {
    for (int u = 0; u < view.width; ++u) {
      const bool shown = v < 90 || v >= 110;
      positions.at<cv::Vec2f>(v, u) = shown ? cv::Vec2f((static_cast<float>(u) + 0.37F) * across,
                                                        (static_cast<float>(v) + 0.61F) * down)
                                            : cv::Vec2f(nan, nan);
    }
  }
  return positions;
}

// The same for a picture that samples the panorama elsewhere (a fixed view, viewPositions()): the
// picture the panorama resized to it.
TEST_F(KernelPathsTest, EveryPathAppliesTheSameCorrectionToAView) {
  const cv::Mat positions = viewPositions(lut_.size);
  const cv::Mat picture = panoramaResizedTo(positions.size());
  expectEveryPathCorrectsAlike(
      picture, [&](PoissonColourCorrection& poisson, cv::Mat& corrected, KernelPath path) {
        poisson.applyAt(poisson.viewSamples(positions), corrected, path);
      });
}

// A view's picture corrected and converted to I420 in one pass, by each path: the picture
// corrected as by the two passes, and the I420 of it.
TEST_F(KernelPathsTest, EveryPathCorrectsAViewAndConvertsItInOnePass) {
  const cv::Mat positions = viewPositions(lut_.size);
  const cv::Mat picture = panoramaResizedTo(positions.size());
  PoissonColourCorrection poisson(truth_.rig, testing::settingsFor(truth_), lut_, {}, pool_);
  poisson.update(frames_);
  const auto samples = poisson.viewSamples(positions);
  cv::Mat twoPasses = picture.clone();
  poisson.applyAt(samples, twoPasses, KernelPath::kPortable);
  cv::Mat expected(i420HeldSize(picture.size()), CV_8UC1);
  bgrRowsToI420(twoPasses, 0, twoPasses.rows, expected, KernelPath::kPortable);
  for (const KernelPath path : kKernelPaths) {
    SCOPED_TRACE(kernelPathName(path));
    cv::Mat corrected = picture.clone();
    cv::Mat i420;
    poisson.applyAt(samples, corrected, i420, path);
    EXPECT_EQ(cv::norm(corrected, twoPasses, cv::NORM_INF), 0.0);
    ASSERT_EQ(i420.size(), expected.size());
    EXPECT_EQ(cv::norm(i420, expected, cv::NORM_INF), 0.0);
  }
}

// Every weight pair (0..128 each) on 2x2 pictures of random bytes, of all 0 and of all 255 (the
// 16-bit lanes' and the packs' limits).
template <KernelPath kPath>
std::vector<std::uint32_t> sampleEveryWeight(const std::vector<cv::Mat>& pictures) {
  std::vector<std::uint32_t> samples;
  for (const cv::Mat& picture : pictures) {
    for (int fy = 0; fy <= LutTap::kFractionOne; ++fy) {
      for (int fx = 0; fx <= LutTap::kFractionOne; ++fx) {
        LutTap tap;
        tap.fx = static_cast<std::uint8_t>(fx);
        tap.fy = static_cast<std::uint8_t>(fy);
        // The weights are those of every format: BGR's neighbours are the picture's bytes.
        samples.push_back(
            bilinear<PixelFormat::kBgr, kPath>(SampledImage::of(picture, PixelFormat::kBgr), tap));
      }
    }
  }
  return samples;
}

template <std::size_t... kIndex>
std::array<std::vector<std::uint32_t>, kKernelPaths.size()> sampleEveryWeightByEveryPath(
    const std::vector<cv::Mat>& pictures, std::index_sequence<kIndex...>) {
  return {sampleEveryWeight<kKernelPaths[kIndex]>(pictures)...};
}

TEST(KernelPaths, EveryPathWeighsAlike) {
  std::vector<cv::Mat> pictures{cv::Mat(2, 2, CV_8UC3, cv::Scalar::all(0)),
                                cv::Mat(2, 2, CV_8UC3, cv::Scalar::all(255))};
  std::mt19937 random(19);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int k = 0; k < 8; ++k) {
    cv::Mat picture(2, 2, CV_8UC3);  // continuous: 12 bytes
    for (int i = 0; i < 12; ++i) picture.data[i] = static_cast<std::uint8_t>(byte(random));
    pictures.push_back(picture);
  }
  const auto samples =
      sampleEveryWeightByEveryPath(pictures, std::make_index_sequence<kKernelPaths.size()>());
  for (std::size_t p = 1; p < kKernelPaths.size(); ++p) {
    SCOPED_TRACE(kernelPathName(kKernelPaths[p]));
    EXPECT_EQ(samples[p], samples[0]);
  }
  // All 255 stays 255 at every weight, all 0 stays 0.
  constexpr std::size_t kWeights =
      std::size_t{LutTap::kFractionOne + 1} * (LutTap::kFractionOne + 1);
  for (std::size_t i = 0; i < kWeights; ++i) {
    ASSERT_EQ(samples[0][i], 0u);
    ASSERT_EQ(samples[0][kWeights + i], 0xffffffu);
  }
}

}  // namespace
}  // namespace surroundd::processing
