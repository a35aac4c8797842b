// H.264 files written by VideoEncoder and read back by FileSource: timestamps kept, pictures close
// to what went in, identical bytes when asked for, nothing half-written left behind.

#include "render/outputs/video_encoder.hpp"

#include <regex>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "common/ffmpeg_util.hpp"
#include "render/outputs/video_sink.hpp"
#include "tests/support/log_capture.hpp"
#include "tests/support/small_disk.hpp"
#include "tests/support/stream_receiver.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::render {
namespace {

using std::chrono::microseconds;
using std::chrono::milliseconds;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// NOLINTNEXTLINE(cert-err58-cpp): cv::Size stores two ints; its constructor throws nothing.
const cv::Size kSize(320, 240);

cv::Mat testPicture(int index) { return testing::syntheticPicture(kSize, index); }

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

void writeVideo(const VideoEncoderSettings& settings, int frames) {
  VideoEncoder encoder(settings);
  for (int i = 0; i < frames; ++i) encoder.write(testPicture(i), timestampOf(i));
  encoder.close();
  EXPECT_EQ(encoder.framesWritten(), static_cast<std::uint64_t>(frames));
}

void writeVideo(const std::filesystem::path& path, int frames) {
  writeVideo(settingsFor(path), frames);
}

// What the container says about its video stream, read with libavformat directly.
struct StreamInfo {
  AVRational timeBase{};
  AVRational averageRate{};
  AVColorRange range = AVCOL_RANGE_UNSPECIFIED;
  AVColorSpace space = AVCOL_SPC_UNSPECIFIED;
  int profile = 0;
};

StreamInfo probe(const std::filesystem::path& path) {
  AVFormatContext* raw = nullptr;
  EXPECT_EQ(avformat_open_input(&raw, path.c_str(), nullptr, nullptr), 0) << path;
  if (raw == nullptr) return {};
  const ffmpeg::InputFormatPtr format(raw);
  EXPECT_GE(avformat_find_stream_info(format.get(), nullptr), 0);
  EXPECT_EQ(format->nb_streams, 1u);
  const AVStream* stream = format->streams[0];
  return {stream->time_base, stream->avg_frame_rate, stream->codecpar->color_range,
          stream->codecpar->color_space, stream->codecpar->profile};
}

using VideoEncoderTest = testing::ContainerTest;

TEST_F(VideoEncoderTest, RoundTripKeepsPicturesAndTimestamps) {
  forEachContainer([&] {
    const auto path = file("video");
    writeVideo(path, 30);
    EXPECT_FALSE(std::filesystem::exists(path.string() + ".part"));
    const auto decoded = testing::decodeAll(path);
    EXPECT_EQ(decoded.last, capture::ReadStatus::kEndOfStream);
    ASSERT_EQ(decoded.images.size(), 30u);
    // Timestamps are absolute (not moved to zero). MP4 keeps microseconds, Matroska milliseconds.
    const auto precision = isMp4() ? microseconds(0) : microseconds(500);
    for (int i = 0; i < 30; ++i) {
      EXPECT_LE(std::chrono::abs(decoded.timestamps[i] - timestampOf(i)), precision) << i;
      EXPECT_GE(cv::PSNR(decoded.images[i], testPicture(i)), 40.0) << i;
    }
  });
}

TEST_F(VideoEncoderTest, StreamIsTaggedForTheConversionBack) {
  forEachContainer([&] {
    const auto path = file("tags");
    writeVideo(path, 3);
    const StreamInfo info = probe(path);
    EXPECT_EQ(info.range, AVCOL_RANGE_MPEG);
    EXPECT_EQ(info.space, AVCOL_SPC_SMPTE170M);
    EXPECT_EQ(info.profile, FF_PROFILE_H264_HIGH_444_PREDICTIVE);
    // MP4 has no field for a nominal rate: readers measure it from the durations (1 / 33333 us).
    EXPECT_NEAR(av_q2d(info.averageRate), 30.0, 0.01);
    EXPECT_EQ(av_cmp_q(info.timeBase, isMp4() ? AVRational{1, 1'000'000} : AVRational{1, 1000}), 0)
        << info.timeBase.num << "/" << info.timeBase.den;
  });
}

TEST_F(VideoEncoderTest, SameInputGivesSameBytes) {
  forEachContainer([&] {
    writeVideo(file("a"), 10);
    writeVideo(file("b"), 10);
    const auto a = testing::fileBytes(file("a"));
    EXPECT_FALSE(a.empty());
    EXPECT_EQ(a, testing::fileBytes(file("b")));
  });
}

TEST_F(VideoEncoderTest, LosslessIsCloserStill) {
  forEachContainer([&] {
    auto settings = settingsFor(file("lossless"));
    settings.crf = 0;
    settings.threads = 0;
    settings.bitExact = false;
    writeVideo(settings, 3);
    const auto decoded = testing::decodeAll(settings.path);
    ASSERT_EQ(decoded.images.size(), 3u);
    // Lossless in YUV; only the BGR <-> YUV rounding remains.
    for (int i = 0; i < 3; ++i) EXPECT_GE(cv::PSNR(decoded.images[i], testPicture(i)), 45.0) << i;
  });
}

TEST_F(VideoEncoderTest, StalePartFileIsOverwritten) {
  forEachContainer([&] {
    const auto path = file("clip");
    const auto part = path.string() + ".part";
    dir_.write(path.filename().string() + ".part", std::string(100'000, 'x'));
    writeVideo(path, 5);
    EXPECT_FALSE(std::filesystem::exists(part));
    EXPECT_EQ(testing::decodeAll(path).images.size(), 5u);
  });
}

TEST_F(VideoEncoderTest, RejectsTimestampsThatDoNotIncrease) {
  forEachContainer([&] {
    const auto path = file("clip");
    VideoEncoder encoder(settingsFor(path));
    encoder.write(testPicture(0), milliseconds(40));
    const auto rejected = ThrowsMessage<EncoderError>(
        AllOf(HasSubstr(path.string()), HasSubstr("timestamps must increase")));
    EXPECT_THAT([&] { encoder.write(testPicture(1), milliseconds(40)); }, rejected);
    EXPECT_THAT([&] { encoder.write(testPicture(1), milliseconds(30)); }, rejected);
    // 0.4 ms later: distinct in MP4, the same millisecond in Matroska.
    if (isMp4()) {
      EXPECT_NO_THROW(encoder.write(testPicture(1), microseconds(40'400)));
    } else {
      EXPECT_THAT([&] { encoder.write(testPicture(1), microseconds(40'400)); }, rejected);
    }
    // A rejected frame leaves the encoder usable.
    encoder.write(testPicture(2), milliseconds(80));
    encoder.close();
    EXPECT_EQ(testing::decodeAll(path).images.size(), isMp4() ? 3u : 2u);
  });
}

TEST_F(VideoEncoderTest, DestructorFinalizesTheFile) {
  forEachContainer([&] {
    {
      VideoEncoder encoder(settingsFor(file("clip")));
      for (int i = 0; i < 4; ++i) encoder.write(testPicture(i), timestampOf(i));
    }
    EXPECT_FALSE(std::filesystem::exists(file("clip").string() + ".part"));
    EXPECT_EQ(testing::decodeAll(file("clip")).images.size(), 4u);
  });
}

TEST(VideoEncoder, RejectsBadSettingsNamingTheFile) {
  const testing::TempDir dir;
  const auto rejects = [](const VideoEncoderSettings& settings, const std::string& why) {
    EXPECT_THAT(
        [&] { VideoEncoder{settings}; },
        ThrowsMessage<EncoderError>(AllOf(HasSubstr(settings.path.string()), HasSubstr(why))))
        << why;
  };
  rejects(settingsFor(dir / "clip.avi"), ".mp4 or .mkv");
  rejects(settingsFor(dir / "clip"), ".mp4 or .mkv");
  auto settings = settingsFor(dir / "odd.mp4");
  settings.size = {321, 240};
  rejects(settings, "even");
  settings.size = {320, 241};
  rejects(settings, "even");
  settings = settingsFor(dir / "rgb.mkv");
  settings.pixelFormat = "rgb24";
  rejects(settings, "pixel format");
  settings = settingsFor(dir / "crf.mkv");
  settings.crf = 60;
  rejects(settings, "crf");
  settings = settingsFor(dir / "fps.mkv");
  settings.nominalFps = 0;
  rejects(settings, "frame rate");
  // Found out only by x264, once the .part file may exist: it must go again.
  settings = settingsFor(dir / "preset.mp4");
  settings.preset = "warp-speed";
  rejects(settings, "warp-speed");
  settings = settingsFor(dir / "no-such-folder" / "clip.mp4");
  rejects(settings, "cannot create");
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));  // nothing half-made, nothing renamed
}

// encoder: auto takes the first hardware encoder that opens, else libx264 and says why each did
// not; on a machine without one (CI's) that is libx264, and the file plays the same.
TEST(VideoEncoder, AutoFallsBackToLibx264SayingWhyEachHardwareEncoderDidNot) {
  const testing::TempDir dir;
  auto settings = settingsFor(dir / "auto.mp4");
  settings.encoder = "auto";
  settings.pixelFormat = "yuv420p";
  settings.bitExact = false;
  const testing::LogCapture log;
  std::string name;
  {
    VideoEncoder encoder(settings);
    name = encoder.encoderName();
    for (int i = 0; i < 5; ++i) encoder.write(testPicture(i), timestampOf(i));
    encoder.close();
  }
  const auto decoded = testing::decodeAll(settings.path);
  ASSERT_EQ(decoded.images.size(), 5u);
  EXPECT_GE(cv::PSNR(decoded.images[4], testPicture(4)), 30.0);
  const auto lines = log.lines();
  ASSERT_EQ(lines.size(), 1u);
  const std::string& line = lines[0];
  EXPECT_THAT(line, HasSubstr(settings.path.string()));
  if (name == "libx264") {
    EXPECT_THAT(line, HasSubstr("H.264 by libx264, as no hardware encoder opens here"));
    for (const char* hardware : kHardwareH264Encoders) EXPECT_THAT(line, HasSubstr(hardware));
  } else {
    EXPECT_THAT(kHardwareH264Encoders, ::testing::Contains(name));
    EXPECT_THAT(line, HasSubstr("H.264 by " + name));
  }
}

// A named encoder is that one or an error naming it; what only x264 does is refused to the others.
TEST(VideoEncoder, ANamedEncoderIsThatOneOrAClearError) {
  const testing::TempDir dir;
  auto settings = settingsFor(dir / "named.mp4");
  settings.encoder = "libx264";
  EXPECT_EQ(VideoEncoder(settings).encoderName(), "libx264");
  std::filesystem::remove(settings.path.string() + ".part");
  settings.pixelFormat = "bgr24";
  EXPECT_EQ(VideoEncoder(settings).encoderName(), "libx264rgb");
  std::filesystem::remove(settings.path.string() + ".part");

  settings.encoder = "h264_nvenc";
  EXPECT_THAT([&] { VideoEncoder{settings}; },
              ThrowsMessage<EncoderError>(HasSubstr("pixel format bgr24 needs libx264")));
  settings.pixelFormat = "yuv420p";
  EXPECT_THAT([&] { VideoEncoder{settings}; },
              ThrowsMessage<EncoderError>(HasSubstr("bit-exact output needs libx264")));
  settings.bitExact = false;
  settings.encoder = "mjpeg";
  EXPECT_THAT([&] { VideoEncoder{settings}; },
              ThrowsMessage<EncoderError>(HasSubstr("'mjpeg' does not encode H.264")));
  settings.encoder = "h264_warp";
  EXPECT_THAT([&] { VideoEncoder{settings}; },
              ThrowsMessage<EncoderError>(HasSubstr("no encoder 'h264_warp'")));
  EXPECT_FALSE(h264EncoderProblem("auto"));
  EXPECT_FALSE(h264EncoderProblem("h264_vaapi"));
  // Without a VA-API device (a machine with no GPU, as CI's) the encoder says so, and nothing is
  // left behind.
  if (!std::filesystem::exists("/dev/dri/renderD128")) {
    settings.encoder = "h264_vaapi";
    EXPECT_THAT([&] { VideoEncoder{settings}; },
                ThrowsMessage<EncoderError>(
                    AllOf(HasSubstr(settings.path.string()), HasSubstr("no VA-API device"))));
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(VideoEncoder, RejectsPicturesOfTheWrongShape) {
  const testing::TempDir dir;
  VideoEncoder encoder(settingsFor(dir / "clip.mkv"));
  const auto rejected = ThrowsMessage<EncoderError>(HasSubstr((dir / "clip.mkv").string()));
  EXPECT_THAT([&] { encoder.write(cv::Mat(kSize / 2, CV_8UC3), milliseconds(0)); }, rejected);
  EXPECT_THAT([&] { encoder.write(cv::Mat(kSize, CV_8UC1), milliseconds(0)); }, rejected);
  EXPECT_THAT([&] { encoder.write(cv::Mat(), milliseconds(0)); }, rejected);
  EXPECT_EQ(encoder.framesWritten(), 0u);
}

// A 4:2:0 stream takes I420 pictures as they are (its maker converted them): the video is the one
// the same pictures in BGR give, but for the two conversions' rounding; a 4:4:4 one takes only BGR.
TEST(VideoEncoder, A420StreamTakesI420PicturesAsTheyAre) {
  const testing::TempDir dir;
  auto settings = settingsFor(dir / "bgr.mkv");
  settings.pixelFormat = "yuv420p";
  settings.crf = 0;
  writeVideo(settings, 3);
  settings.path = dir / "i420.mkv";
  {
    VideoEncoder encoder(settings);
    EXPECT_TRUE(encoder.takesI420());
    for (int i = 0; i < 3; ++i) {
      cv::Mat i420;
      cv::cvtColor(testPicture(i), i420, cv::COLOR_BGR2YUV_I420);
      encoder.write(i420, timestampOf(i));
    }
    encoder.close();
  }
  const auto fromBgr = testing::decodeAll(dir / "bgr.mkv");
  const auto fromI420 = testing::decodeAll(settings.path);
  ASSERT_EQ(fromI420.images.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    // Lossless (crf 0): what comes back is the I420 that went in, converted back (the decoder
    // interpolates the chroma where OpenCV repeats it: 37 dB at this picture's sharp edges).
    cv::Mat i420;
    cv::Mat expected;
    cv::cvtColor(testPicture(i), i420, cv::COLOR_BGR2YUV_I420);
    cv::cvtColor(i420, expected, cv::COLOR_YUV2BGR_I420);
    EXPECT_GE(cv::PSNR(fromI420.images[static_cast<std::size_t>(i)], expected), 35.0);
    EXPECT_GE(cv::PSNR(fromI420.images[static_cast<std::size_t>(i)],
                       fromBgr.images[static_cast<std::size_t>(i)]),
              35.0);
  }
  settings.path = dir / "444.mkv";
  settings.pixelFormat = "yuv444p";
  VideoEncoder full(settings);
  EXPECT_FALSE(full.takesI420());
  cv::Mat i420;
  cv::cvtColor(testPicture(0), i420, cv::COLOR_BGR2YUV_I420);
  EXPECT_THAT([&] { full.write(i420, milliseconds(0)); },
              ThrowsMessage<EncoderError>(HasSubstr("expected an 8-bit BGR picture of 320x240")));
}

TEST(VideoEncoder, CloseWithoutFramesThrowsAndLeavesNothing) {
  const testing::TempDir dir;
  VideoEncoder encoder(settingsFor(dir / "clip.mp4"));
  EXPECT_TRUE(std::filesystem::exists(dir / "clip.mp4.part"));
  EXPECT_THAT([&] { encoder.close(); }, ThrowsMessage<EncoderError>(HasSubstr("no frames")));
  EXPECT_NO_THROW(encoder.close());  // idempotent
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(VideoEncoder, CloseIsIdempotentAndEndsWriting) {
  const testing::TempDir dir;
  VideoEncoder encoder(settingsFor(dir / "clip.mkv"));
  encoder.write(testPicture(0), milliseconds(0));
  encoder.close();
  const auto bytes = testing::fileBytes(dir / "clip.mkv");
  EXPECT_NO_THROW(encoder.close());
  EXPECT_THAT([&] { encoder.write(testPicture(1), milliseconds(40)); },
              ThrowsMessage<EncoderError>(HasSubstr("after close")));
  EXPECT_EQ(testing::fileBytes(dir / "clip.mkv"), bytes);
  EXPECT_EQ(encoder.path(), dir / "clip.mkv");
}

// Issue 51: on a full disk the encoder deleted its whole .part file (21 of 229 frames survived the
// attack). Now the file that holds frames is ended where it stands and keeps its name, playable
// (MKV, and MP4 in fragments of a second), and the error says so; no file is begun on a disk that
// is all but full, and one is again once there is room.
TEST(VideoEncoder, AFullDiskKeepsWhatWasWrittenPlayable) {
  for (const std::string name : {"full.mp4", "full.mkv"}) {
    testing::SmallDisk disk(std::uintmax_t{24} << 20);
    if (!disk.problem().empty()) GTEST_SKIP() << disk.problem();
    disk.fill(std::uintmax_t{10} << 20);
    auto settings = settingsFor(disk / name);
    settings.crf = 0;  // lossless: about a megabyte a second here, and the pictures come back
    VideoEncoder encoder(settings);
    std::string error;
    int sent = 0;
    for (; sent < 2000 && error.empty(); ++sent) {
      cv::Mat noise(kSize, CV_8UC3);
      cv::randu(noise, 0, 256);
      cv::Mat picture = testPicture(sent);
      cv::addWeighted(picture, 0.5, noise, 0.5, 0, picture);
      try {
        encoder.write(picture, timestampOf(sent));
      } catch (const EncoderError& e) {
        error = e.what();
      }
    }
    std::smatch kept;
    ASSERT_TRUE(std::regex_search(
        error, kept,
        std::regex("cannot write to the file: No space left on device; '(.*)' keeps the first "
                   "([0-9]+) of ([0-9]+) frames encoded, playable")))
        << error;
    EXPECT_EQ(kept[1].str(), (disk / name).string());
    EXPECT_NO_THROW(encoder.close());  // ended already
    EXPECT_FALSE(std::filesystem::exists(disk / (name + ".part"))) << name;
    const auto decoded = testing::decodeAll(disk / name);
    // At least the first fragment (a second's 30 frames), each at its own time; as many as said.
    EXPECT_GE(decoded.images.size(), 30u) << name;
    EXPECT_LT(decoded.images.size(), static_cast<std::size_t>(sent)) << name;
    EXPECT_NEAR(static_cast<double>(decoded.images.size()), std::stod(kept[2].str()), 1) << name;
    for (std::size_t i = 0; i < decoded.timestamps.size(); ++i) {
      EXPECT_NEAR(
          std::chrono::duration<double>(decoded.timestamps[i] - timestampOf(static_cast<int>(i)))
              .count(),
          0.0, 1e-3)
          << name << " frame " << i;
    }

    // The disk all but full: refused before anything is written; with room again, written.
    disk.fill(std::uintmax_t{1} << 20);
    auto next = settings;
    next.path = disk / ("next-" + name);
    EXPECT_THAT([&] { VideoEncoder{next}; },
                ThrowsMessage<EncoderError>(
                    AllOf(HasSubstr("the disk is full"), HasSubstr("less than the 8 MiB"))));
    EXPECT_FALSE(std::filesystem::exists(next.path.string() + ".part"));
    disk.empty();
    writeVideo(next, 5);
    EXPECT_EQ(testing::decodeAll(next.path).images.size(), 5u);
  }
}

// From a review: a full disk early in an MP4, at a rate where its first fragments are large. What
// the error says is kept is what plays: the frames a player reads back, or no file at all where
// none reached it (an MP4 without its index plays nothing, and is not left under the name).
TEST(VideoEncoder, AFullDiskEarlyInAnMp4KeepsWhatPlaysAndSaysHowMuch) {
  testing::SmallDisk disk(std::uintmax_t{24} << 20);
  if (!disk.problem().empty()) GTEST_SKIP() << disk.problem();
  disk.fill(std::uintmax_t{9} << 20);
  auto settings = settingsFor(disk / "early.mp4");
  settings.size = {640, 480};  // noise, losslessly: about a megabyte a frame
  settings.crf = 0;
  VideoEncoder encoder(settings);
  std::string error;
  for (int sent = 0; sent < 200 && error.empty(); ++sent) {
    cv::Mat noise(settings.size, CV_8UC3);
    cv::randu(noise, 0, 256);
    try {
      encoder.write(noise, timestampOf(sent));
    } catch (const EncoderError& e) {
      error = e.what();
    }
  }
  EXPECT_FALSE(std::filesystem::exists(disk / "early.mp4.part"));
  std::smatch kept;
  if (std::regex_search(error, kept,
                        std::regex("keeps the first ([0-9]+) of ([0-9]+) frames encoded"))) {
    EXPECT_NEAR(static_cast<double>(testing::decodeAll(disk / "early.mp4").images.size()),
                std::stod(kept[1].str()), 1);
    EXPECT_LT(std::stoi(kept[1].str()), std::stoi(kept[2].str()));
  } else {
    EXPECT_THAT(error, HasSubstr("frames encoded reached the file; no file kept"));
    EXPECT_FALSE(std::filesystem::exists(disk / "early.mp4"));
  }
}

TEST(VideoSink, SegmentsAreWholePlayableFilesAndARestartNumbersOn) {
  const testing::TempDir dir;
  auto settings = settingsFor(dir / "drive.mp4");
  const auto write = [&](int first, int count) {
    VideoSink sink(settings, std::chrono::seconds(1));
    for (int i = first; i < first + count; ++i) sink.consume(testPicture(i), timestampOf(i));
    sink.finish({}, {});
    return sink.describe();
  };
  // 2.5 s at 30 fps: 1 s, 1 s and 0.5 s.
  EXPECT_THAT(write(0, 75), HasSubstr("(3 segments, 75 frames)"));
  std::vector<capture::Timestamp> timestamps;
  for (const auto& [name, frames] :
       {std::pair{"drive-00001.mp4", 30}, {"drive-00002.mp4", 30}, {"drive-00003.mp4", 15}}) {
    const auto decoded = testing::decodeAll(dir / name);
    EXPECT_EQ(decoded.last, capture::ReadStatus::kEndOfStream) << name;
    EXPECT_EQ(decoded.images.size(), static_cast<std::size_t>(frames)) << name;
    timestamps.insert(timestamps.end(), decoded.timestamps.begin(), decoded.timestamps.end());
  }
  // Together, the segments hold every frame at its own time.
  ASSERT_EQ(timestamps.size(), 75u);
  for (int i = 0; i < 75; ++i) {
    EXPECT_NEAR(std::chrono::duration<double>(timestamps[i] - timestampOf(i)).count(), 0.0, 1e-6);
  }
  // Started again (after a crash or a restart): nothing is overwritten.
  EXPECT_THAT(write(75, 10), HasSubstr("drive-00004.mp4 .. drive-00004.mp4 (1 segments"));
  EXPECT_EQ(testing::decodeAll(dir / "drive-00001.mp4").images.size(), 30u);
  EXPECT_FALSE(std::filesystem::exists(dir / "drive.mp4"));

  // A segment a killed run left unfinished (its .part) is kept: numbering goes on after it.
  dir.write("drive-00005.mp4.part", "frames of a killed run");
  EXPECT_THAT(write(85, 5), HasSubstr("drive-00006.mp4 .."));
  EXPECT_EQ(testing::fileBytes(dir / "drive-00005.mp4.part"), "frames of a killed run");

  // Beside a stray segment of the highest int (UBSan saw the next number wrap to -2147483648),
  // numbering goes on; beside one at the end of the numbers it stops with the file named.
  dir.write("drive-2147483647.mp4", "");
  EXPECT_THAT(write(90, 5), HasSubstr("drive-2147483648.mp4 .."));
  // Issue 51: past the largest int64 too, where the next number wrapped to a negative one and a
  // later run overwrote files: numbers of any length past the end stop it with the file named.
  for (const std::string past :
       {"999999999999", "9223372036854775807", "99999999999999999999999"}) {
    const testing::TempDir other;
    other.write("drive-" + past + ".mp4", "");
    VideoEncoderSettings elsewhere = settings;
    elsewhere.path = other / "drive.mp4";
    EXPECT_THAT([&] { VideoSink(elsewhere, std::chrono::seconds(1)); },
                ::testing::ThrowsMessage<EncoderError>(
                    AllOf(HasSubstr("drive-999999999999.mp4"), HasSubstr("move them away"))))
        << past;
  }
  // A sign is no part of a segment's number.
  dir.write("drive--5.mp4", "");
  dir.write("drive-+7000000.mp4", "");
  EXPECT_THAT(write(95, 5), HasSubstr("drive-2147483649.mp4 .."));
}

TEST(VideoSink, StreamsMpegTsOverUdpThatAReceiverDecodesToTheSentPictures) {
  const int port = testing::freeUdpPort();
  testing::StreamReceiver receiver(port, std::chrono::seconds(2));
  VideoEncoderSettings settings;
  settings.url = fmt::format("udp://127.0.0.1:{}", port);
  settings.size = kSize;
  settings.crf = 18;
  VideoSink sink(settings);
  for (int i = 0; i < 45; ++i) {
    sink.consume(testPicture(i), timestampOf(i));
    std::this_thread::sleep_for(milliseconds(5));  // paced a little, as frames come live
  }
  sink.finish({}, {});
  EXPECT_THAT(sink.describe(),
              HasSubstr(fmt::format("stream udp://127.0.0.1:{} (45 frames)", port)));
  const auto pictures = receiver.pictures();
  ASSERT_EQ(pictures.size(), 45u) << receiver.error();
  // 4:2:0 at crf 18 on hard colour edges: a little below what the 4:4:4 files reach.
  for (int i = 0; i < 45; ++i) EXPECT_GE(cv::PSNR(pictures[i].bgr, testPicture(i)), 30.0) << i;
}

TEST(VideoSink, ANetworkAddressOtherThanUdpIsRefused) {
  VideoEncoderSettings settings;
  settings.url = "tcp://127.0.0.1:9";
  settings.size = kSize;
  EXPECT_THAT([&] { VideoSink sink(settings); },
              ThrowsMessage<EncoderError>(
                  HasSubstr("stream 'tcp://127.0.0.1:9': expected a udp://HOST:PORT address")));
}

}  // namespace
}  // namespace surroundd::render
