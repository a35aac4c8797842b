// Camera frames held as the camera gave them (YUYV, NV12: issue 19.3) are sampled straight from
// their YUV: per pixel the conversion is cv::cvtColor's, bit for bit; a stitch of the held frames
// agrees with converting each whole frame to BGR first and stitching that, and colour correction
// measures the seams alike from either — on the synth_small recording's first frame set.

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "common/pixel_format.hpp"
#include "common/work_pool.hpp"
#include "processing/colour/gain_compensation.hpp"
#include "processing/colour/poisson_correction.hpp"
#include "processing/stitch/bilinear_sample.hpp"
#include "processing/stitch/stitcher.hpp"
#include "processing/stitch/yuv_lanes.hpp"
#include "tests/processing/panorama_test_support.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::processing {
namespace {

constexpr std::array kYuvFormats = {PixelFormat::kYuyv, PixelFormat::kUyvy, PixelFormat::kNv12};

// Every Y, Cb, Cr: a YUYV picture per luma level whose pairs hold each Cb (across) and Cr (down).
TEST(YuvToBgr, IsCvtColorsConversionOfEveryYuv) {
  cv::Mat yuyv(256, 512, CV_8UC2);
  cv::Mat bgr;
  for (int luma = 0; luma < 256; ++luma) {
    for (int cr = 0; cr < 256; ++cr) {
      auto* row = yuyv.ptr<std::uint8_t>(cr);
      for (int cb = 0; cb < 256; ++cb) {
        std::uint8_t* pair = row + std::ptrdiff_t{4} * cb;
        pair[0] = pair[2] = static_cast<std::uint8_t>(luma);
        pair[1] = static_cast<std::uint8_t>(cb);
        pair[3] = static_cast<std::uint8_t>(cr);
      }
    }
    cv::cvtColor(yuyv, bgr, cv::COLOR_YUV2BGR_YUYV);
    int differing = 0;
    for (int cr = 0; cr < 256; ++cr) {
      for (int cb = 0; cb < 256; ++cb) {
        const cv::Vec3b expected = bgr.at<cv::Vec3b>(cr, 2 * cb);
        const std::uint32_t got = yuvToBgr(static_cast<std::uint32_t>(luma | cb << 8 | cr << 16));
        const std::uint32_t packed = expected[0] | expected[1] << 8 | expected[2] << 16;
        differing += got != packed ? 1 : 0;
      }
    }
    ASSERT_EQ(differing, 0) << "luma " << luma;
  }
}

// The stitcher's SIMD conversion of two pixels at once (yuv_lanes.hpp) against yuvToBgr() for every
// Y, Cb, Cr in either lane, the other lane holding a different pixel and the ignored lanes garbage.
TEST(YuvToBgr, TheSimdLanesConvertEveryYuvAsOnePixelIs) {
#if defined(__SSE2__) || defined(__ARM_NEON)
  const auto convert = [](std::uint32_t a, std::uint32_t b) {
    std::array<std::uint16_t, 8> lanes{};
    for (int c = 0; c < 3; ++c) {
      lanes[static_cast<std::size_t>(c)] = static_cast<std::uint16_t>((a >> (8 * c)) & 0xffU);
      lanes[static_cast<std::size_t>(c) + 4] = static_cast<std::uint16_t>((b >> (8 * c)) & 0xffU);
    }
    lanes[3] = static_cast<std::uint16_t>(a >> 24);
    lanes[7] = 255;
    std::array<std::uint8_t, 8> bytes{};
#if defined(__SSE2__)
    __m128i words;
    std::memcpy(&words, lanes.data(), sizeof words);
    const __m128i packed = _mm_packus_epi16(yuvToBgrLanes(words), yuvToBgrLanes(words));
    std::memcpy(bytes.data(), &packed, bytes.size());
#else
    vst1_u8(bytes.data(), vqmovun_s16(yuvToBgrLanes(vld1q_u16(lanes.data()))));
#endif
    std::uint64_t both = 0;
    std::memcpy(&both, bytes.data(), bytes.size());
    return both;
  };
  int differing = 0;
  for (std::uint32_t yuv = 0; yuv < (1U << 24); ++yuv) {
    const std::uint32_t other = yuv ^ 0x5a3c96U;
    const std::uint64_t expected = yuvToBgr(yuv) | std::uint64_t{yuvToBgr(other)} << 32;
    differing += convert(yuv | 0xab000000U, other) != expected ? 1 : 0;
  }
  EXPECT_EQ(differing, 0);
#else
  GTEST_SKIP() << "this build has no SIMD kernels (kernel_path.hpp)";
#endif
}

// An NV12 tap's row is found without a division (rowOf()): exact for every row of frames up to
// 16 Mpixels, and for the last rows that 32-bit offsets reach.
TEST(YuvSampling, AnNv12TapsRowIsItsOffsetOverTheWidth) {
  for (const std::uint32_t width : {2U, 640U, 854U, 1280U, 1920U, 2592U, 4096U, 8190U, 65534U}) {
    SampledImage image;
    image.width = width;
    image.rowReciprocal = rowReciprocalOf(width);
    const std::uint32_t lastRow = ~std::uint32_t{0} / width - 1;
    const auto wrongIn = [&](std::uint32_t firstRow, std::uint32_t endRow) {
      int wrong = 0;
      for (std::uint32_t y = firstRow; y < endRow; ++y) {
        for (const std::uint32_t x : {0U, 1U, width / 2, width - 1}) {
          wrong += rowOf(image, y * width + x) != y ? 1 : 0;
        }
      }
      return wrong;
    };
    EXPECT_EQ(wrongIn(0, std::min((1U << 24) / width, lastRow)), 0) << "width " << width;
    EXPECT_EQ(wrongIn(lastRow - std::min(lastRow, 1U << 16), lastRow + 1), 0) << "width " << width;
  }
}

class YuvSamplingTest : public ::testing::Test {
 protected:
  YuvSamplingTest()
      : truth_(testing::smallRecording()),
        lut_(buildPanoramaLut(truth_.rig, testing::settingsFor(truth_), pool_)) {
    for (const auto& video : truth_.videos) {
      frames_.push_back(surroundd::testing::decodeAll(video, false, 1).images.at(0));
    }
  }

  // The frames as a camera of `format` delivers them, and those converted back to BGR whole.
  struct Held {
    std::vector<cv::Mat> frames;
    std::vector<cv::Mat> converted;
  };
  Held held(PixelFormat format) const {
    Held held;
    for (const cv::Mat& frame : frames_) {
      bgrToHeld(frame, format, held.frames.emplace_back());
      heldToBgr(held.frames.back(), format, held.converted.emplace_back());
    }
    return held;
  }

  WorkPool pool_{2};
  const bench::RecordingTruth& truth_;
  PanoramaLut lut_;
  std::vector<cv::Mat> frames_;
};

TEST_F(YuvSamplingTest, APixelOfAHeldFrameIsThatOfTheWholeFrameConverted) {
  for (const PixelFormat format : kYuvFormats) {
    SCOPED_TRACE(toString(format));
    const Held frames = held(format);
    const cv::Mat& frame = frames.frames[0];
    const cv::Mat& converted = frames.converted[0];
    int differing = 0;
    for (int y = 0; y < converted.rows; ++y) {
      for (int x = 0; x < converted.cols; ++x) {
        const cv::Vec3b expected = converted.at<cv::Vec3b>(y, x);
        differing += bgrAt(frame, format, x, y) !=
                             (expected[0] | expected[1] << 8 | std::uint32_t{expected[2]} << 16)
                         ? 1
                         : 0;
      }
    }
    EXPECT_EQ(differing, 0);
  }
}

// A tap on a whole pixel reads that pixel: exactly the converted frame's. Between pixels the YUV
// is interpolated before its conversion, where the converted frame is interpolated after it: the
// conversion is affine, so the two agree but for rounding (the interpolated YUV is rounded to 8
// bits, and the conversion scales luma by 1.16 and chroma by up to 2.02: a level) and clamping.
// Clamping matters only where subsampled chroma meets a sharp colour edge: a luma with its
// neighbour's chroma can lie outside the RGB cube, and clamping each pixel before interpolating
// differs from clamping the result. Measured on this recording: 0.4 % of the channels a level or
// more apart, 0.03 % (YUYV) and 0.06 % (NV12) more than 2, at most 12 and 15 levels; the mean
// difference 0.14-0.19 of a level, no bias.
TEST_F(YuvSamplingTest, AStitchOfHeldFramesIsThatOfTheFramesConvertedFirst) {
  Stitcher stitcher(lut_, pool_);
  for (const PixelFormat format : kYuvFormats) {
    SCOPED_TRACE(toString(format));
    const Held frames = held(format);
    const SampledImage image = SampledImage::of(frames.frames[0], format);
    const SampledImage converted = SampledImage::of(frames.converted[0], PixelFormat::kBgr);
    const cv::Size size = frames.converted[0].size();
    for (int y = 0; y + 1 < size.height; ++y) {
      for (int x = 0; x + 1 < size.width; ++x) {
        LutTap tap;
        tap.offset = static_cast<std::uint32_t>(y * size.width + x);
        ASSERT_EQ(bilinear(image, tap), bilinear(converted, tap)) << x << ", " << y;
      }
    }

    cv::Mat fromHeld;
    cv::Mat fromConverted;
    stitcher.stitch(frames.frames, format, fromHeld);
    stitcher.stitch(frames.converted, fromConverted);
    cv::Mat difference;
    cv::absdiff(fromHeld, fromConverted, difference);
    const cv::Scalar mean = cv::mean(difference);
    const cv::Mat levels = difference.reshape(1);
    const auto shareOver = [&levels](int apart) {
      return cv::countNonZero(levels > apart) / static_cast<double>(levels.total());
    };
    EXPECT_LT(shareOver(1), 0.01);
    EXPECT_LT(shareOver(2), 0.002);
    for (int c = 0; c < 3; ++c) EXPECT_LT(mean[c], 0.3) << "channel " << c;
    cv::Mat signedDifference;
    cv::subtract(fromHeld, fromConverted, signedDifference, cv::noArray(), CV_16SC3);
    const cv::Scalar bias = cv::mean(signedDifference);
    for (int c = 0; c < 3; ++c) EXPECT_LT(std::abs(bias[c]), 0.1) << "channel " << c;
  }
}

TEST_F(YuvSamplingTest, ColourCorrectionMeasuresHeldFramesAsConvertedOnes) {
  for (const PixelFormat format : kYuvFormats) {
    SCOPED_TRACE(toString(format));
    const Held frames = held(format);
    ColourCorrectionSettings settings;
    PoissonColourCorrection fromHeld(truth_.rig, testing::settingsFor(truth_), lut_, settings,
                                     pool_);
    PoissonColourCorrection fromConverted(truth_.rig, testing::settingsFor(truth_), lut_, settings,
                                          pool_);
    fromHeld.update(frames.frames, format);
    fromConverted.update(frames.converted);
    // The same seams measured, but for a block or two whose levels sit at the edge of what is
    // usable (4 or 250); the same steps left; fields a level and a half apart on average (in
    // levels at 255; measured 1.5), where they change pictures by up to 215.
    const cv::Mat& field = fromConverted.field();
    ASSERT_GT(cv::norm(field, cv::NORM_INF), 50.0);  // a field that corrects
    EXPECT_LT(
        cv::norm(fromHeld.field(), field, cv::NORM_L1) / static_cast<double>(field.total() * 3),
        3.0);
    ASSERT_EQ(fromHeld.seams().size(), fromConverted.seams().size());
    for (std::size_t i = 0; i < fromHeld.seams().size(); ++i) {
      const auto& fromYuv = fromHeld.seams()[i];
      const auto& fromBgr = fromConverted.seams()[i];
      SCOPED_TRACE("seam " + std::to_string(i));
      EXPECT_NEAR(fromYuv.validBlocks, fromBgr.validBlocks, 2);
      EXPECT_NEAR(fromYuv.stepUncorrected, fromBgr.stepUncorrected, 0.5);
      EXPECT_LT(fromYuv.stepCorrected, fromBgr.stepCorrected + 1.0);
      EXPECT_FALSE(fromYuv.dropped);
    }

    // Gain compensation fits medians of 8-bit levels: a level's shift in one at 50 is 2 %.
    GainCompensation gainsFromHeld(lut_, pool_);
    GainCompensation gainsFromConverted(lut_, pool_);
    gainsFromHeld.update(frames.frames, format);
    gainsFromConverted.update(frames.converted);
    for (std::size_t i = 0; i < gainsFromHeld.gains().size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        const float expected = gainsFromConverted.gains()[i][c];
        EXPECT_NEAR(gainsFromHeld.gains()[i][c], expected, 0.03 * expected)
            << "camera " << i << " channel " << c;
      }
    }
  }
}

}  // namespace
}  // namespace surroundd::processing
