// Recordings played from memory as a camera delivers them: the generator's recording, preloaded as
// YUYV, UYVY or NV12, gives the frames FileSource decodes (within what the camera format's chroma
// subsampling and 8-bit YUV round trip lose) with the same timestamps; it loops, paces, and refuses
// what does not fit its memory bound or its format, naming the camera and the file.

#include "capture/preloaded_source.hpp"

#include <chrono>
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "capture/jpeg_decoder.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::capture {
namespace {

using std::chrono::milliseconds;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// 320x180, 1 s at 30 FPS (tests/fixtures.cmake). A function: a static path's construction could
// throw before main (cert-err58-cpp).
std::filesystem::path video() {
  return std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_small" / "front.mkv";
}
constexpr std::size_t kFrames = 30;
constexpr int kMaxReads = 10'000;  // bounds every read loop: a source that never ends fails

PreloadSettings preload(const std::filesystem::path& path, PixelLayout format, bool loop = false,
                        Pacing pacing = Pacing::kAsFastAsPossible) {
  PreloadSettings settings;
  settings.file = {path, 30.0, loop, pacing};
  settings.format = format;
  return settings;
}

struct Played {
  std::vector<cv::Mat> images;  // BGR
  std::vector<cv::Mat> held;    // as the source held them
  std::vector<Timestamp> timestamps;
  std::vector<std::uint64_t> sequences;
};

Played play(FrameSource& source, std::size_t limit = kMaxReads) {
  Frame frame;
  frame.format = source.pixelFormat();
  frame.image.create(heldSize(frame.format, source.frameSize()), heldType(frame.format));
  Played played;
  while (played.images.size() < limit && source.read(frame) == ReadStatus::kFrame) {
    heldToBgr(frame.image, frame.format, played.images.emplace_back());
    played.held.push_back(frame.image.clone());
    played.timestamps.push_back(frame.timestamp);
    played.sequences.push_back(frame.sequence);
  }
  return played;
}

class PreloadedFormat : public ::testing::TestWithParam<PixelLayout> {};

// The tolerance is the round trip's: BGR -> 8-bit YUV (BT.601, limited range) -> BGR loses what
// the format's chroma subsampling drops (YUYV: one colour for two pixels of a row; NV12: for 2x2)
// and a level of rounding. Measured on this recording (textured ground, sensor noise), frame by
// frame: YUYV a mean absolute difference of at most 0.65 levels and PSNR of at least 42.8 dB, NV12
// 1.01 levels and 38.9 dB; single pixels at sharp colour edges differ by up to 51 (YUYV) and 81
// (NV12) levels, which is the subsampling, and no channel is off on average by more than 0.05 of
// a level. The bounds (mean 1.0 / 1.5 levels, PSNR 40 / 36 dB, bias 0.3 of a level) leave room
// for other FFmpeg and OpenCV builds and catch a wrong matrix or range (a bias of several levels),
// a level and a half of bias (libswscale's packed 4:2:2 output had that) or a swapped plane.
TEST_P(PreloadedFormat, FramesAreTheDecodedOnesThroughTheCameraFormat) {
  const PixelLayout format = GetParam();
  FileSource decoding("front", {video(), 30.0, false, Pacing::kAsFastAsPossible});
  PreloadedSource preloaded("front", preload(video(), format));
  ASSERT_EQ(preloaded.frameSize(), decoding.frameSize());
  EXPECT_EQ(preloaded.nominalPeriod(), decoding.nominalPeriod());
  EXPECT_EQ(preloaded.frameCount(), kFrames);
  EXPECT_EQ(preloaded.bytes(), kFrames * preloadedFrameBytes(format, {320, 180}));
  EXPECT_FALSE(preloaded.repeatsOnePicture());

  const Played expected = play(decoding);
  const Played got = play(preloaded);
  ASSERT_EQ(got.images.size(), kFrames);
  ASSERT_EQ(expected.images.size(), kFrames);
  EXPECT_EQ(got.timestamps, expected.timestamps);
  EXPECT_EQ(got.sequences, expected.sequences);
  const bool packed = format != PixelLayout::kNv12;  // YUYV, UYVY: 4:2:2 in one plane
  const double maxMean = packed ? 1.0 : 1.5;
  const double minPsnr = packed ? 40.0 : 36.0;
  JpegDecoder jpeg;
  for (std::size_t i = 0; i < kFrames; ++i) {
    cv::Mat difference;
    cv::absdiff(got.images[i], expected.images[i], difference);
    const cv::Scalar mean = cv::mean(difference);
    EXPECT_LT((mean[0] + mean[1] + mean[2]) / 3, maxMean) << "frame " << i;
    EXPECT_GT(cv::PSNR(got.images[i], expected.images[i]), minPsnr) << "frame " << i;
    cv::Mat gotLevels;
    cv::Mat expectedLevels;
    got.images[i].convertTo(gotLevels, CV_32F);
    expected.images[i].convertTo(expectedLevels, CV_32F);
    const cv::Scalar bias = cv::mean(gotLevels - expectedLevels);
    for (int channel = 0; channel < 3; ++channel) {
      EXPECT_LT(std::abs(bias[channel]), 0.3) << "frame " << i << " channel " << channel;
    }
    // Handed over as the camera hands it over, byte for byte, in a frame that says so; and
    // converted as a V4L2 camera's frames would be: the same bytes give the same picture.
    const auto data = preloaded.frameData(i);
    ASSERT_EQ(data.size(), preloadedFrameBytes(format, {320, 180}));
    EXPECT_EQ(preloaded.pixelFormat(), heldFormat(format));
    EXPECT_NE(preloaded.pixelFormat(), PixelFormat::kBgr);
    ASSERT_EQ(got.held[i].total() * got.held[i].elemSize(), data.size());
    EXPECT_TRUE(std::equal(data.begin(), data.end(), got.held[i].ptr<std::uint8_t>()))
        << "frame " << i;
    cv::Mat converted(180, 320, CV_8UC3);
    std::string error;
    ASSERT_TRUE(convertToBgr(format, data, packed ? 640 : 320, jpeg, converted, error)) << error;
    EXPECT_EQ(cv::norm(converted, got.images[i], cv::NORM_INF), 0.0) << "frame " << i;
  }
  // Limited range: luma (YUYV's even bytes, UYVY's odd ones, NV12's first plane) within 16..235.
  const auto first = preloaded.frameData(0);
  const std::size_t lumaBytes = packed ? first.size() : std::size_t{320} * 180;
  const std::size_t step = packed ? 2 : 1;
  std::uint8_t low = 255;
  std::uint8_t high = 0;
  for (std::size_t b = format == PixelLayout::kUyvy ? 1 : 0; b < lumaBytes; b += step) {
    low = std::min(low, first[b]);
    high = std::max(high, first[b]);
  }
  EXPECT_GE(low, 16);
  EXPECT_LE(high, 235);
}

INSTANTIATE_TEST_SUITE_P(YuyvUyvyAndNv12, PreloadedFormat,
                         ::testing::Values(PixelLayout::kYuyv, PixelLayout::kUyvy,
                                           PixelLayout::kNv12),
                         [](const ::testing::TestParamInfo<PixelLayout>& format) {
                           return std::string(toString(format.param));
                         });

TEST(PreloadedSource, PlaysOnceAndEnds) {
  PreloadedSource source("front", preload(video(), PixelLayout::kYuyv));
  EXPECT_EQ(play(source).images.size(), kFrames);
  Frame frame;
  frame.image.create(source.frameSize(), CV_8UC3);
  EXPECT_EQ(source.read(frame), ReadStatus::kEndOfStream);
  EXPECT_EQ(source.read(frame), ReadStatus::kEndOfStream);
}

// Each pass shows the same frames; timestamps move on by whole periods (the recording's 30 frames
// span 29 periods: each pass starts 30 periods after the one before), the sequence keeps counting.
TEST(PreloadedSource, LoopsWithIncreasingTimestamps) {
  PreloadedSource source("front", preload(video(), PixelLayout::kNv12, true));
  const Played played = play(source, 2 * kFrames + 5);
  ASSERT_EQ(played.images.size(), 2 * kFrames + 5);
  const Timestamp pass = static_cast<std::int64_t>(kFrames) * source.nominalPeriod();
  for (std::size_t i = kFrames; i < played.images.size(); ++i) {
    EXPECT_EQ(cv::norm(played.images[i], played.images[i - kFrames], cv::NORM_INF), 0.0) << i;
    EXPECT_EQ(played.timestamps[i], played.timestamps[i - kFrames] + pass) << i;
  }
  for (std::size_t i = 1; i < played.images.size(); ++i) {
    EXPECT_GT(played.timestamps[i], played.timestamps[i - 1]) << i;
    EXPECT_EQ(played.sequences[i], i);
  }
}

// Real time: frames come at the recording's rate; as fast as possible: at once. Only bounds that
// hold on a loaded machine: ten frames paced span nine periods (300 ms); all thirty unpaced take
// far less than their 29 periods (967 ms).
TEST(PreloadedSource, PacesInRealTimeOrPlaysAsFastAsPossible) {
  PreloadedSource paced("front", preload(video(), PixelLayout::kYuyv, false, Pacing::kRealtime));
  auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(play(paced, 10).images.size(), 10u);
  EXPECT_GE(std::chrono::steady_clock::now() - start, milliseconds(280));

  PreloadedSource fast("front", preload(video(), PixelLayout::kYuyv));
  start = std::chrono::steady_clock::now();
  EXPECT_EQ(play(fast).images.size(), kFrames);
  EXPECT_LT(std::chrono::steady_clock::now() - start, milliseconds(900));
}

// 320x180 YUYV is 115200 bytes a frame, 3456000 for the 30: refused before any decoding, with the
// camera, the file, the bytes needed and allowed and where the bound comes from.
TEST(PreloadedSource, MoreThanTheMemoryBoundIsRefusedNamingNeededAndAllowedBytes) {
  // Matroska states no frame count: the hint is its duration over the frame period.
  EXPECT_EQ(FileSource("front", {video(), 30.0, false, Pacing::kAsFastAsPossible}).frameCountHint(),
            kFrames);
  auto settings = preload(video(), PixelLayout::kYuyv);
  settings.maxBytes = 3456000 - 1;
  settings.maxBytesOrigin = "the test's bound";
  EXPECT_THAT([&] { PreloadedSource("front", settings); },
              ThrowsMessage<CaptureError>(
                  AllOf(HasSubstr("camera 'front'"), HasSubstr(video().string()),
                        HasSubstr("preloaded as YUYV needs 3456000 bytes"),
                        HasSubstr("30 frames of 320x180, 115200 bytes each"),
                        HasSubstr("more than the 3455999 bytes (3.3 MiB) allowed by the test's "
                                  "bound"))));
  settings.maxBytes = 3456000;  // exactly fits
  EXPECT_EQ(PreloadedSource("front", settings).bytes(), 3456000u);
}

// Pictures whose size the format cannot hold, and formats a file is not preloaded in.
TEST(PreloadedSource, AFormatOrSizeItCannotHoldIsRefused) {
  const testing::TempDir dir;
  cv::imwrite((dir / "odd_width.png").string(), testing::syntheticPicture({161, 120}, 0));
  cv::imwrite((dir / "odd_height.png").string(), testing::syntheticPicture({160, 121}, 0));
  const auto refused = [](const std::filesystem::path& path, PixelLayout format,
                          const std::string& reason) {
    EXPECT_THAT([&] { PreloadedSource("left", preload(path, format)); },
                ThrowsMessage<CaptureError>(
                    AllOf(HasSubstr("camera 'left'"), HasSubstr(path.string()), HasSubstr(reason))))
        << path << " " << toString(format);
  };
  refused(dir / "odd_width.png", PixelLayout::kYuyv, "161x120 frames, which YUYV cannot hold");
  refused(dir / "odd_height.png", PixelLayout::kNv12,
          "160x121 frames, which NV12 cannot hold (it needs an even width and height)");
  EXPECT_EQ(
      PreloadedSource("left", preload(dir / "odd_height.png", PixelLayout::kYuyv)).frameCount(),
      1u);
  refused(video(), PixelLayout::kMjpeg, "cannot be preloaded as MJPEG: only as YUYV, UYVY or NV12");
  refused(dir / "missing.mkv", PixelLayout::kYuyv, "cannot open");
}

// A still picture preloaded is one frame, shown again every period when looped.
TEST(PreloadedSource, AStillPictureIsOneFrameRepeated) {
  const testing::TempDir dir;
  cv::imwrite((dir / "still.png").string(), testing::syntheticPicture({160, 120}, 3));
  PreloadedSource source("left", preload(dir / "still.png", PixelLayout::kYuyv, true));
  EXPECT_TRUE(source.repeatsOnePicture());
  const Played played = play(source, 4);
  ASSERT_EQ(played.images.size(), 4u);
  EXPECT_EQ(played.timestamps[3] - played.timestamps[0], 3 * source.nominalPeriod());
}

}  // namespace
}  // namespace surroundd::capture
