// H.264 files written by VideoEncoder and read back by FileSource: timestamps kept, pictures close
// to what went in, identical bytes when asked for, nothing half-written left behind.

#include "render/video_encoder.hpp"

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "capture/file_source.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd::render {
namespace {

using std::chrono::microseconds;
using std::chrono::milliseconds;
using ::testing::HasSubstr;

const cv::Size kSize(320, 240);

// A picture with smooth gradients, edges and a shape that moves with `index`.
cv::Mat testPicture(int index) {
  cv::Mat image(kSize, CV_8UC3);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<std::uint8_t>(x * 255 / kSize.width),
                                            static_cast<std::uint8_t>(y * 255 / kSize.height),
                                            static_cast<std::uint8_t>((x + y + index * 4) % 256));
    }
  }
  cv::circle(image, {40 + index * 6, 120}, 30, cv::Scalar(20, 200, 240), cv::FILLED);
  cv::rectangle(image, {200, 40 + index * 3}, {260, 90 + index * 3}, cv::Scalar(250, 40, 40),
                cv::FILLED);
  return image;
}

VideoEncoderSettings settingsFor(const std::filesystem::path& path) {
  VideoEncoderSettings settings;
  settings.path = path;
  settings.size = kSize;
  settings.crf = 12;
  settings.pixelFormat = "yuv444p";
  settings.threads = 1;
  settings.bitExact = true;
  return settings;
}

// Frames at 30 fps that start 3.25 ms after zero, as a camera of a rig would.
std::chrono::nanoseconds timestampOf(int index) {
  return microseconds(3250) + index * microseconds(33333);
}

void writeVideo(const std::filesystem::path& path, int frames) {
  VideoEncoder encoder(settingsFor(path));
  for (int i = 0; i < frames; ++i) encoder.write(testPicture(i), timestampOf(i));
  encoder.close();
  EXPECT_EQ(encoder.framesWritten(), static_cast<std::uint64_t>(frames));
}

struct Decoded {
  std::vector<cv::Mat> images;
  std::vector<capture::Timestamp> timestamps;
};

Decoded decode(const std::filesystem::path& path, bool loop = false, int limit = 1000) {
  capture::FileSource source("test", {path, 30.0, loop, capture::Pacing::kAsFastAsPossible});
  capture::Frame frame;
  frame.image.create(source.frameSize(), CV_8UC3);
  Decoded decoded;
  while (limit-- > 0 && source.read(frame) == capture::ReadStatus::kFrame) {
    decoded.images.push_back(frame.image.clone());
    decoded.timestamps.push_back(frame.timestamp);
  }
  return decoded;
}

std::string bytesOf(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), {}};
}

class VideoEncoderTest : public ::testing::TestWithParam<std::string> {
 protected:
  testing::TempDir dir_;
};

TEST_P(VideoEncoderTest, RoundTripKeepsPicturesAndTimestamps) {
  const auto path = dir_ / ("video" + GetParam());
  writeVideo(path, 30);
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".part"));
  const Decoded decoded = decode(path);
  ASSERT_EQ(decoded.images.size(), 30u);
  // Matroska keeps milliseconds. MP4 keeps microseconds between frames, but its start offset
  // (an edit list) only to the millisecond.
  const auto start = decoded.timestamps[0] - timestampOf(0);
  EXPECT_LE(std::chrono::abs(start), microseconds(1000));
  const auto precision = GetParam() == ".mp4" ? microseconds(1) : microseconds(1000);
  for (int i = 0; i < 30; ++i) {
    EXPECT_LE(std::chrono::abs(decoded.timestamps[i] - start - timestampOf(i)), precision) << i;
    EXPECT_GE(cv::PSNR(decoded.images[i], testPicture(i)), 40.0) << i;
  }
}

TEST_P(VideoEncoderTest, SameInputGivesSameBytes) {
  writeVideo(dir_ / ("a" + GetParam()), 10);
  writeVideo(dir_ / ("b" + GetParam()), 10);
  const auto a = bytesOf(dir_ / ("a" + GetParam()));
  const auto b = bytesOf(dir_ / ("b" + GetParam()));
  EXPECT_EQ(a, b);
}

TEST_P(VideoEncoderTest, LoopingKeepsTimestampsIncreasing) {
  const auto path = dir_ / ("loop" + GetParam());
  writeVideo(path, 5);
  const Decoded decoded = decode(path, true, 12);
  ASSERT_EQ(decoded.images.size(), 12u);
  for (std::size_t i = 1; i < decoded.timestamps.size(); ++i) {
    EXPECT_GT(decoded.timestamps[i], decoded.timestamps[i - 1]) << i;
  }
  EXPECT_GE(cv::PSNR(decoded.images[5], testPicture(0)), 40.0);  // the content starts again
}

INSTANTIATE_TEST_SUITE_P(Containers, VideoEncoderTest, ::testing::Values(".mp4", ".mkv"));

TEST(VideoEncoder, RejectsBadSettingsNamingTheFile) {
  const testing::TempDir dir;
  auto settings = settingsFor(dir / "clip.avi");
  EXPECT_THAT([&] { VideoEncoder{settings}; },
              ::testing::ThrowsMessage<EncoderError>(HasSubstr("clip.avi")));
  settings = settingsFor(dir / "odd.mp4");
  settings.size = {321, 240};
  EXPECT_THAT([&] { VideoEncoder{settings}; },
              ::testing::ThrowsMessage<EncoderError>(HasSubstr("even")));
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));  // nothing half-made
}

TEST(VideoEncoder, RejectsTimestampsThatDoNotIncrease) {
  const testing::TempDir dir;
  VideoEncoder encoder(settingsFor(dir / "clip.mp4"));
  encoder.write(testPicture(0), milliseconds(40));
  EXPECT_THAT([&] { encoder.write(testPicture(1), milliseconds(40)); },
              ::testing::ThrowsMessage<EncoderError>(HasSubstr("timestamps must increase")));
}

TEST(VideoEncoder, DestructorFinalizesTheFile) {
  const testing::TempDir dir;
  {
    VideoEncoder encoder(settingsFor(dir / "clip.mkv"));
    for (int i = 0; i < 4; ++i) encoder.write(testPicture(i), timestampOf(i));
  }
  EXPECT_EQ(decode(dir / "clip.mkv").images.size(), 4u);
}

}  // namespace
}  // namespace surroundd::render
