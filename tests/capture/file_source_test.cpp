// File-backed virtual cameras: videos and image sequences replay with their timestamps and
// pictures; bad input gives a clear error naming the camera and the file at start, or faults and
// ends mid-stream — never a crash or a hang.

#include "capture/file_source.hpp"

#include <algorithm>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/sequence_pattern.hpp"
#include "render/outputs/video_encoder.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::capture {
namespace {

using std::chrono::microseconds;
using std::chrono::milliseconds;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

const cv::Size kSize(160, 120);    // NOLINT(cert-err58-cpp): two ints, nothing to throw
constexpr int kMaxReads = 10'000;  // bounds every read loop: a source that never ends fails

cv::Mat picture(int index) { return testing::syntheticPicture(kSize, index); }

cv::Mat noise(int seed) {
  cv::Mat image(96, 128, CV_8UC3);
  cv::RNG(static_cast<std::uint64_t>(seed)).fill(image, cv::RNG::UNIFORM, 0, 256);
  return image;
}

FileSourceSettings fastSettings(const std::filesystem::path& path, bool loop = false) {
  return {path, 30.0, loop, Pacing::kAsFastAsPossible};
}

// 30 fps from 0 (0, 33333 us, 66666 us, ...), leaving out the frames in `gaps`.
std::vector<microseconds> writeClip(const std::filesystem::path& path, int frames,
                                    std::vector<int> gaps = {}) {
  render::VideoEncoderSettings settings;
  settings.path = path;
  settings.size = kSize;
  settings.crf = 12;
  settings.pixelFormat = "yuv444p";  // 4:2:0 alone costs ~5 dB on these small, sharp pictures
  settings.threads = 1;
  settings.bitExact = true;
  render::VideoEncoder encoder(settings);
  std::vector<microseconds> timestamps;
  for (int i = 0; i < frames; ++i) {
    if (std::find(gaps.begin(), gaps.end(), i) != gaps.end()) continue;
    timestamps.emplace_back(i * 100'000 / 3);
    encoder.write(picture(i), timestamps.back());
  }
  encoder.close();
  return timestamps;
}

void expectOpenError(const std::filesystem::path& path, std::string_view reason) {
  EXPECT_THAT(
      [&] { FileSource("front", fastSettings(path)); },
      ::testing::ThrowsMessage<CaptureError>(AllOf(
          HasSubstr("camera 'front'"), HasSubstr(path.string()), HasSubstr(std::string(reason)))))
      << path;
}

// Reads until the end, a cap, or (with `stopAtFault`) the first fault.
std::vector<ReadStatus> readStatuses(FileSource& source, bool stopAtFault = false) {
  Frame frame;
  frame.image.create(source.frameSize(), CV_8UC3);
  std::vector<ReadStatus> statuses;
  for (int reads = 0; reads < kMaxReads; ++reads) {
    statuses.push_back(source.read(frame));
    if (statuses.back() == ReadStatus::kFault) {
      EXPECT_THAT(source.lastError(), HasSubstr("camera 'front'"));
      if (stopAtFault) break;
    }
    if (statuses.back() == ReadStatus::kEndOfStream) break;
  }
  return statuses;
}

TEST(FileSource, BadFilesFailAtStartNamingCameraAndFile) {
  const testing::TempDir dir;
  expectOpenError(dir / "absent.mkv", "No such file or directory");
  expectOpenError(dir / "absent_%04d.png", "No such file or directory");
  expectOpenError(dir.write("empty.mkv", ""), "");
  cv::Mat bytes(1, 8192, CV_8U);
  cv::RNG(7).fill(bytes, cv::RNG::UNIFORM, 0, 256);
  expectOpenError(dir.write("garbage.mkv", std::string(bytes.ptr<char>(), 8192)), "");
  expectOpenError(dir.write("notes.mp4", "these are notes, not a video\n"), "");

  // A valid WAV file: it opens, but holds no pictures.
  std::string wav = "RIFF";
  const auto le32 = [&wav](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) wav.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  };
  le32(36 + 1600);
  wav += "WAVEfmt ";
  le32(16);
  le32(0x00010001);  // PCM, mono
  le32(8000);        // samples per second
  le32(16000);       // bytes per second
  le32(0x00100002);  // 2 bytes per sample, 16 bits
  wav += "data";
  le32(1600);
  wav += std::string(1600, '\0');
  expectOpenError(dir.write("sound.wav", wav), "no video stream");
}

using FileSourceVideo = testing::ContainerTest;

TEST_F(FileSourceVideo, ReplaysPicturesAndTimestampsWithGaps) {
  forEachContainer([&] {
    const auto path = file("clip");
    const auto written = writeClip(path, 20, {7, 12, 13});
    FileSource source("front", fastSettings(path));
    EXPECT_EQ(source.frameSize(), kSize);
    // MKV stores the nominal rate; MP4 has no field for it, so readers average the durations, which
    // the gaps stretch (17 frames over 20 periods: 39 ms).
    EXPECT_NEAR(static_cast<double>(source.nominalPeriod().count()), isMp4() ? 39.2e6 : 33.33e6,
                0.1e6);
    Frame frame;
    frame.image.create(source.frameSize(), CV_8UC3);
    const auto* buffer = frame.image.data;
    std::vector<int> indices;
    for (int i = 0; i < 20; ++i) {
      if (i != 7 && i != 12 && i != 13) indices.push_back(i);
    }
    ASSERT_EQ(written.size(), indices.size());
    // MP4 keeps microseconds; Matroska milliseconds.
    const auto precision = isMp4() ? microseconds(0) : microseconds(500);
    for (std::size_t k = 0; k < indices.size(); ++k) {
      ASSERT_EQ(source.read(frame), ReadStatus::kFrame) << k << ": " << source.lastError();
      EXPECT_EQ(frame.image.data, buffer);  // decoded straight into the caller's buffer
      EXPECT_EQ(frame.sequence, k);
      EXPECT_LE(std::chrono::abs(frame.timestamp - written[k]), precision) << k;
      EXPECT_GE(cv::PSNR(frame.image, picture(indices[k])), 35.0) << k;
    }
    EXPECT_EQ(source.read(frame), ReadStatus::kEndOfStream);
    EXPECT_EQ(source.read(frame), ReadStatus::kEndOfStream);
  });
}

// Two cameras of a rig whose last frames came a few milliseconds apart (clock jitter) still loop by
// the same offset: otherwise they would drift apart pass by pass until no frames match.
TEST_F(FileSourceVideo, CamerasWithJitteredLastFramesLoopByTheSameOffset) {
  forEachContainer([&] {
    const auto write = [&](const std::string& stem, microseconds lastJitter) {
      render::VideoEncoderSettings settings;
      settings.path = file(stem);
      settings.size = kSize;
      settings.threads = 1;
      render::VideoEncoder encoder(settings);
      for (int i = 0; i < 10; ++i) {
        encoder.write(picture(i),
                      microseconds(33333 * i) + (i == 9 ? lastJitter : microseconds(0)));
      }
    };
    write("early", microseconds(-4000));
    write("late", microseconds(4000));
    const auto timestampsOf = [&](const std::string& stem) {
      FileSource source(stem, fastSettings(file(stem), true));
      Frame frame;
      frame.image.create(source.frameSize(), CV_8UC3);
      std::vector<Timestamp> timestamps;
      for (int i = 0; i < 50; ++i) {
        EXPECT_EQ(source.read(frame), ReadStatus::kFrame);
        timestamps.push_back(frame.timestamp);
      }
      return timestamps;
    };
    const auto early = timestampsOf("early");
    const auto late = timestampsOf("late");
    for (std::size_t pass = 1; pass < 5; ++pass) {
      EXPECT_EQ(early[pass * 10] - early[0], late[pass * 10] - late[0]) << "pass " << pass;
      EXPECT_NEAR(std::chrono::duration<double>(early[pass * 10] - early[0]).count(),
                  static_cast<double>(pass) * 10 / 30.0, 1e-3);
    }
  });
}

TEST_F(FileSourceVideo, LoopingRestartsWithIncreasingTimestamps) {
  forEachContainer([&] {
    const auto path = file("loop");
    writeClip(path, 5);
    FileSource source("front", fastSettings(path, true));
    EXPECT_NEAR(static_cast<double>(source.nominalPeriod().count()), 33'333'333, 2000);
    Frame frame;
    frame.image.create(source.frameSize(), CV_8UC3);
    std::vector<Timestamp> timestamps;
    for (int i = 0; i < 12; ++i) {
      ASSERT_EQ(source.read(frame), ReadStatus::kFrame) << i << ": " << source.lastError();
      EXPECT_EQ(frame.sequence, static_cast<std::uint64_t>(i));
      EXPECT_GE(cv::PSNR(frame.image, picture(i % 5)), 35.0) << i;  // the content starts again
      timestamps.push_back(frame.timestamp);
    }
    for (std::size_t i = 1; i < timestamps.size(); ++i) {
      EXPECT_GT(timestamps[i], timestamps[i - 1]) << i;
    }
    // The next pass starts a whole number of periods after the first: one after the last frame.
    EXPECT_EQ(timestamps[5] - timestamps[0], 5 * source.nominalPeriod());
    EXPECT_EQ(timestamps[10] - timestamps[5], timestamps[5] - timestamps[0]);
  });
}

TEST_F(FileSourceVideo, TruncatedFileFailsCleanlyOrEnds) {
  forEachContainer([&] {
    const auto path = file("cut");
    {
      render::VideoEncoder encoder({path, {128, 96}, 30.0, 10, "veryfast", "yuv420p", 1, true, ""});
      for (int i = 0; i < 40; ++i) encoder.write(noise(i), milliseconds(33 * i));
    }
    std::filesystem::resize_file(path, std::filesystem::file_size(path) * 6 / 10);
    try {
      FileSource source("front", fastSettings(path));
      const auto statuses = readStatuses(source);
      ASSERT_LT(statuses.size(), static_cast<std::size_t>(kMaxReads));
      EXPECT_EQ(statuses.back(), ReadStatus::kEndOfStream);
      EXPECT_LT(std::count(statuses.begin(), statuses.end(), ReadStatus::kFrame), 40);
    } catch (const CaptureError& e) {
      // Failing at start is fine too (MP4 keeps its index at the end, which is cut off).
      EXPECT_THAT(e.what(), AllOf(HasSubstr("camera 'front'"), HasSubstr(path.string())));
    }
  });
}

TEST_F(FileSourceVideo, CorruptDataFaultsAndEnds) {
  forEachContainer([&] {
    const auto path = file("corrupt");
    writeClip(path, 30);
    const auto size = static_cast<std::streamoff>(std::filesystem::file_size(path));
    {
      std::fstream file(path, std::ios::binary | std::ios::in | std::ios::out);
      cv::Mat bytes(1, 3000, CV_8U);
      cv::RNG(11).fill(bytes, cv::RNG::UNIFORM, 0, 256);
      file.seekp(size / 2);
      file.write(bytes.ptr<char>(), 3000);
    }
    FileSource source("front", fastSettings(path));  // the first frames are intact
    const auto statuses = readStatuses(source);
    ASSERT_LT(statuses.size(), static_cast<std::size_t>(kMaxReads));
    EXPECT_EQ(statuses.back(), ReadStatus::kEndOfStream);
    EXPECT_GE(std::count(statuses.begin(), statuses.end(), ReadStatus::kFrame), 5);
  });
}

TEST_F(FileSourceVideo, PercentInAFileNameIsNotASequence) {
  forEachContainer([&] {
    const auto path = file("100%");
    writeClip(path, 3);
    EXPECT_EQ(testing::decodeAll(path).images.size(), 3u);
  });
}

TEST(FileSource, ImageSequenceReplaysExactly) {
  const testing::TempDir dir;
  for (int i = 0; i < 5; ++i) {
    cv::imwrite((dir / cv::format("front_%04d.png", i)).string(), noise(i));
  }
  FileSource source("front", {dir / "front_%04d.png", 25.0, false, Pacing::kAsFastAsPossible});
  EXPECT_EQ(source.frameSize(), cv::Size(128, 96));
  EXPECT_EQ(source.nominalPeriod(), milliseconds(40));
  Frame frame;
  frame.image.create(source.frameSize(), CV_8UC3);
  for (int i = 0; i < 5; ++i) {
    ASSERT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
    EXPECT_EQ(cv::norm(frame.image, noise(i), cv::NORM_INF), 0.0) << i;
    EXPECT_EQ(frame.timestamp, milliseconds(40 * i));  // index / fps
    EXPECT_EQ(frame.sequence, static_cast<std::uint64_t>(i));
  }
  EXPECT_EQ(source.read(frame), ReadStatus::kEndOfStream);
}

// Only one %d or %0Nd makes a file name a pattern (FFmpeg's image2 rule); any other '%' leaves it
// a plain name, which nothing formats (issue 18: "%s%s%s" was a crash, "%999999999d" 16 s).
TEST(SequencePattern, OnlyOneIntegerConversionMakesAPattern) {
  EXPECT_EQ(classifyFileName("front_%06d.png"), FileNameKind::kSequence);
  EXPECT_EQ(classifyFileName("front_%d.png"), FileNameKind::kSequence);
  EXPECT_EQ(classifyFileName("100%%_%03d.png"), FileNameKind::kSequence);
  for (const char* plain : {"front.png", "100%.png", "x%s%s%s%s.png", "x%n%n%n.png", "x%d_%d.png",
                            "x%d%s.png", "x%", "x%%d.png"}) {
    EXPECT_EQ(classifyFileName(plain), FileNameKind::kPlainFile) << plain;
  }
  EXPECT_EQ(classifyFileName("x%999999999d.png"), FileNameKind::kTooWide);
  EXPECT_EQ(classifyFileName("x%33d.png"), FileNameKind::kTooWide);
  EXPECT_EQ(classifyFileName("x%032d.png"), FileNameKind::kSequence);
  EXPECT_EQ(sequenceFrameName("front_%06d.png", 42), "front_000042.png");
  EXPECT_EQ(sequenceFrameName("100%%_%d.png", 7), "100%_7.png");
  EXPECT_THROW(sequenceFrameName("x%s%d.png", 1), std::invalid_argument);
  EXPECT_THROW(sequenceFrameName("x%999999999d.png", 1), std::invalid_argument);
}

TEST(FileSource, APictureWithPercentsInItsNameIsAStill) {
  const testing::TempDir dir;
  const auto path = dir / "x%s%s%n%d%d.png";
  cv::imwrite(path.string(), picture(2));
  EXPECT_TRUE(isStillPicturePath(path));
  FileSource source("front", {path, 10.0, true, Pacing::kAsFastAsPossible});
  EXPECT_TRUE(source.repeatsOnePicture());
  Frame frame;
  frame.image.create(source.frameSize(), CV_8UC3);
  ASSERT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
  EXPECT_EQ(cv::norm(frame.image, picture(2), cv::NORM_INF), 0.0);
}

TEST(FileSource, ATooWideSequenceNumberIsRefused) {
  const testing::TempDir dir;
  EXPECT_THAT(
      [&] {
        FileSource("front", {dir / "x%999999999d.png", 10.0});
      },
      ThrowsMessage<CaptureError>(
          AllOf(HasSubstr("camera 'front'"), HasSubstr("wider than 32 digits"))));
}

// A picture a config names besides its cameras (a body mask) is read as a camera would read it:
// a PNG's pixels exactly, a grey one in all three channels; a file with no picture is named.
TEST(FileSource, APictureIsReadAsItsPixels) {
  const testing::TempDir dir;
  cv::imwrite((dir / "colour.png").string(), picture(3));
  EXPECT_EQ(cv::norm(readPicture(dir / "colour.png"), picture(3), cv::NORM_INF), 0.0);
  cv::Mat grey;
  cv::cvtColor(picture(3), grey, cv::COLOR_BGR2GRAY);
  cv::imwrite((dir / "grey.png").string(), grey);
  std::vector<cv::Mat> channels;
  cv::split(readPicture(dir / "grey.png"), channels);
  ASSERT_EQ(channels.size(), 3U);
  for (const cv::Mat& channel : channels) EXPECT_EQ(cv::norm(channel, grey, cv::NORM_INF), 0.0);
  std::ofstream(dir / "text.png") << "not a picture\n";
  EXPECT_THAT([&] { (void)readPicture(dir / "text.png"); },
              ThrowsMessage<CaptureError>(HasSubstr("text.png")));
}

// A still picture as a camera: played at sequence_fps, looped with timestamps one period apart.
TEST(FileSource, StillPictureLoopsAtTheSequenceRate) {
  const testing::TempDir dir;
  for (const char* name : {"still.png", "still.JPG"}) {
    SCOPED_TRACE(name);
    cv::imwrite((dir / name).string(), picture(4), {cv::IMWRITE_JPEG_QUALITY, 95});
    const cv::Mat expected = cv::imread((dir / name).string());
    EXPECT_TRUE(isStillPicturePath(dir / name));
    FileSource source("front", {dir / name, 10.0, true, Pacing::kAsFastAsPossible});
    EXPECT_EQ(source.frameSize(), kSize);
    EXPECT_EQ(source.nominalPeriod(), milliseconds(100));
    EXPECT_TRUE(source.repeatsOnePicture());
    Frame frame;
    frame.image.create(source.frameSize(), CV_8UC3);
    for (int i = 0; i < 50; ++i) {
      ASSERT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
      EXPECT_EQ(frame.timestamp, milliseconds(100 * i));
      EXPECT_EQ(frame.sequence, static_cast<std::uint64_t>(i));
    }
    cv::Mat difference;
    cv::absdiff(frame.image, expected, difference);
    EXPECT_LT(cv::mean(difference)[0], 1.5);  // JPEG: FFmpeg's decoding against OpenCV's
  }
  // Not looped, it is one frame.
  FileSource once("front", fastSettings(dir / "still.png"));
  EXPECT_FALSE(once.repeatsOnePicture());
  EXPECT_EQ(readStatuses(once), (std::vector{ReadStatus::kFrame, ReadStatus::kEndOfStream}));
  EXPECT_FALSE(isStillPicturePath(dir / "front_%04d.png"));
  EXPECT_FALSE(isStillPicturePath(dir / "front.mkv"));
}

TEST(FileSource, OnlyASequenceOfOnePictureRepeatsIt) {
  const testing::TempDir dir;
  cv::imwrite((dir / "one_0.png").string(), noise(1));
  for (int i = 0; i < 3; ++i) cv::imwrite((dir / cv::format("three_%d.png", i)).string(), noise(i));
  FileSource one("front", fastSettings(dir / "one_%d.png", true));
  EXPECT_TRUE(one.repeatsOnePicture());
  Frame frame;
  frame.image.create(one.frameSize(), CV_8UC3);
  for (int i = 0; i < 5; ++i) {
    ASSERT_EQ(one.read(frame), ReadStatus::kFrame);
    EXPECT_EQ(cv::norm(frame.image, noise(1), cv::NORM_INF), 0.0);
    EXPECT_EQ(frame.timestamp, std::chrono::nanoseconds(33'333'333 * i));
  }
  FileSource three("front", fastSettings(dir / "three_%d.png", true));
  EXPECT_FALSE(three.repeatsOnePicture());
}

TEST(FileSource, FullRangeSourcesKeepTheirLevels) {
  const testing::TempDir dir;
  // Gray PNG: full-range gray, which must come out exactly.
  cv::Mat gray;
  cv::cvtColor(noise(3), gray, cv::COLOR_BGR2GRAY);
  cv::imwrite((dir / "gray_0.png").string(), gray);
  auto gray3 = testing::decodeAll(dir / "gray_%d.png");
  ASSERT_EQ(gray3.images.size(), 1u);
  cv::Mat expected;
  cv::cvtColor(gray, expected, cv::COLOR_GRAY2BGR);
  EXPECT_EQ(cv::norm(gray3.images[0], expected, cv::NORM_INF), 0.0);

  // JPEG: full-range YUV. Read as limited range it would gain contrast (about 8 levels at the
  // ends), which the comparison with OpenCV's own decoding catches.
  cv::imwrite((dir / "photo_0.jpg").string(), picture(2), {cv::IMWRITE_JPEG_QUALITY, 95});
  auto photo = testing::decodeAll(dir / "photo_%d.jpg");
  ASSERT_EQ(photo.images.size(), 1u);
  const cv::Mat reference = cv::imread((dir / "photo_0.jpg").string());
  EXPECT_GE(cv::PSNR(photo.images[0], reference), 35.0);
  cv::Mat difference;
  cv::absdiff(photo.images[0], reference, difference);
  EXPECT_LT(cv::mean(difference)[0], 1.5);
}

TEST(FileSource, SizeChangeMidStreamFaultsAndGoesOn) {
  const testing::TempDir dir;
  cv::imwrite((dir / "f_0.png").string(), noise(0));
  cv::Mat larger;
  cv::resize(noise(1), larger, {256, 192});
  cv::imwrite((dir / "f_1.png").string(), larger);
  cv::imwrite((dir / "f_2.png").string(), noise(2));
  FileSource source("front", fastSettings(dir / "f_%d.png"));
  Frame frame;
  frame.image.create(source.frameSize(), CV_8UC3);
  EXPECT_EQ(source.read(frame), ReadStatus::kFrame);
  EXPECT_EQ(source.read(frame), ReadStatus::kFault);
  EXPECT_THAT(source.lastError(), AllOf(HasSubstr("camera 'front'"), HasSubstr("256x192")));
  ASSERT_EQ(source.read(frame), ReadStatus::kFrame);
  EXPECT_EQ(cv::norm(frame.image, noise(2), cv::NORM_INF), 0.0);
  EXPECT_EQ(frame.timestamp, std::chrono::nanoseconds(66'666'667));  // 2 / 30 s
  EXPECT_EQ(source.read(frame), ReadStatus::kEndOfStream);
}

TEST(FileSource, RealtimePacingFollowsTheTimestamps) {
  const testing::TempDir dir;
  for (int i = 0; i < 10; ++i) cv::imwrite((dir / cv::format("f_%02d.png", i)).string(), noise(i));
  FileSource source("front", {dir / "f_%02d.png", 30.0, false, Pacing::kRealtime});
  Frame frame;
  frame.image.create(source.frameSize(), CV_8UC3);
  const auto start = std::chrono::steady_clock::now();
  int frames = 0;
  while (frames < kMaxReads && source.read(frame) == ReadStatus::kFrame) ++frames;
  EXPECT_EQ(frames, 10);
  // Nine periods of 1/30 s (0.3 s) lie between the first and the last frame; only a lower bound
  // is safe on a shared machine.
  EXPECT_GE(std::chrono::steady_clock::now() - start, milliseconds(250));
}

}  // namespace
}  // namespace surroundd::capture
