// File-backed virtual cameras on bad input: each gives a clear error naming the camera and the file
// at start, or faults and ends mid-stream — never a crash or a hang. Image sequences replay
// exactly.

#include "capture/file_source.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "render/video_encoder.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd::capture {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

FileSourceSettings settingsFor(const std::filesystem::path& path) {
  return {path, 30.0, false, Pacing::kAsFastAsPossible};
}

void expectOpenError(const std::filesystem::path& path, std::string_view reason) {
  EXPECT_THAT(
      [&] { FileSource("front", settingsFor(path)); },
      ::testing::ThrowsMessage<CaptureError>(AllOf(
          HasSubstr("camera 'front'"), HasSubstr(path.string()), HasSubstr(std::string(reason)))))
      << path;
}

cv::Mat noise(int seed) {
  cv::Mat image(96, 128, CV_8UC3);
  cv::RNG(static_cast<std::uint64_t>(seed)).fill(image, cv::RNG::UNIFORM, 0, 256);
  return image;
}

TEST(FileSource, MissingEmptyAndGarbageFilesFailAtStart) {
  const testing::TempDir dir;
  expectOpenError(dir / "absent.mkv", "No such file");
  expectOpenError(dir.write("empty.mkv", ""), "");
  expectOpenError(dir.write("garbage.mp4", std::string(4096, '\x5a')), "");
  expectOpenError(dir.write("notes.mp4", "these are notes, not a video\n"), "");
}

TEST(FileSource, TruncatedFileEndsWithoutHanging) {
  const testing::TempDir dir;
  const auto path = dir / "clip.mkv";
  {
    render::VideoEncoder encoder({path, {128, 96}, 30.0, 10, "veryfast", "yuv420p", 1, true});
    for (int i = 0; i < 40; ++i) encoder.write(noise(i), std::chrono::milliseconds(33 * i));
  }
  std::filesystem::resize_file(path, std::filesystem::file_size(path) * 6 / 10);
  try {
    FileSource source("front", settingsFor(path));
    Frame frame;
    frame.image.create(source.frameSize(), CV_8UC3);
    int frames = 0;
    ReadStatus status = ReadStatus::kFrame;
    for (int reads = 0; reads < 10000; ++reads) {
      status = source.read(frame);
      if (status == ReadStatus::kEndOfStream) break;
      if (status == ReadStatus::kFrame) ++frames;
      if (status == ReadStatus::kFault) {
        EXPECT_THAT(source.lastError(), HasSubstr("camera 'front'"));
      }
    }
    EXPECT_EQ(status, ReadStatus::kEndOfStream);
    EXPECT_LT(frames, 40);
  } catch (const CaptureError& e) {
    EXPECT_THAT(e.what(), HasSubstr(path.string()));  // failing at start is fine too
  }
}

TEST(FileSource, ImageSequenceReplaysExactly) {
  const testing::TempDir dir;
  for (int i = 0; i < 5; ++i)
    cv::imwrite((dir / cv::format("front_%04d.png", i)).string(), noise(i));
  FileSource source("front", {dir / "front_%04d.png", 25.0, false, Pacing::kAsFastAsPossible});
  EXPECT_EQ(source.frameSize(), cv::Size(128, 96));
  EXPECT_EQ(source.nominalPeriod(), std::chrono::milliseconds(40));
  Frame frame;
  frame.image.create(source.frameSize(), CV_8UC3);
  for (int i = 0; i < 5; ++i) {
    ASSERT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
    EXPECT_EQ(cv::norm(frame.image, noise(i), cv::NORM_INF), 0.0) << i;
    EXPECT_EQ(frame.timestamp, std::chrono::milliseconds(40 * i));
  }
  EXPECT_EQ(source.read(frame), ReadStatus::kEndOfStream);
}

TEST(FileSource, RealtimePacingFollowsTheTimestamps) {
  const testing::TempDir dir;
  for (int i = 0; i < 10; ++i) cv::imwrite((dir / cv::format("f_%02d.png", i)).string(), noise(i));
  FileSource source("front", {dir / "f_%02d.png", 30.0, false, Pacing::kRealtime});
  Frame frame;
  frame.image.create(source.frameSize(), CV_8UC3);
  const auto start = std::chrono::steady_clock::now();
  while (source.read(frame) == ReadStatus::kFrame) {
  }
  // Nine periods of 1/30 s lie between the first and the last frame; only a lower bound is safe on
  // a shared machine.
  EXPECT_GE(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(290));
}

}  // namespace
}  // namespace surroundd::capture
