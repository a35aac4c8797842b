// One recovery policy for every source kind (issue 18.8): the policy's steps on their own clock,
// then through CameraStream with the fake V4L2 device (a corrupt MJPEG stream, an unplugged camera)
// and a replayed file whose frames decode with errors: each fault counted, the log bounded.

#include "capture/source_recovery.hpp"

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include "capture/camera_stream.hpp"
#include "capture/file_source.hpp"
#include "capture/v4l2_source.hpp"
#include "render/outputs/video_encoder.hpp"
#include "tests/capture/fake_v4l2_device.hpp"
#include "tests/support/log_capture.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::capture {
namespace {

using std::chrono::milliseconds;
using ::testing::HasSubstr;
using Step = SourceRecovery::Step;

// NOLINTNEXTLINE(cert-err58-cpp): cv::Size stores two ints; its constructor throws nothing.
const cv::Size kSize(320, 240);

using testing::LogCapture;

RecoverySettings fastSettings() {
  RecoverySettings settings;
  settings.firstBackoff = milliseconds(20);
  settings.maxBackoff = milliseconds(80);
  return settings;
}

TEST(SourceRecovery, ALostDeviceBacksOffDoublingUpToTheCapAndStartsOverAfterAFrame) {
  const LogCapture log;
  SourceRecovery recovery("front", fastSettings());
  const auto t0 = SourceRecovery::Clock::now();
  EXPECT_EQ(recovery.onFault("corrupt frame", false, t0), Step::kReadAgain);
  EXPECT_EQ(recovery.backoff(), milliseconds(0));
  std::vector<milliseconds> waits;
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(recovery.onFault("gone", true, t0), Step::kReopen);
    waits.push_back(recovery.backoff());
  }
  EXPECT_EQ(waits, (std::vector<milliseconds>{milliseconds(20), milliseconds(40), milliseconds(80),
                                              milliseconds(80), milliseconds(80)}));
  recovery.onReopened(t0);
  EXPECT_EQ(recovery.onFault("opened, but stalled again", true, t0), Step::kReopen);
  EXPECT_EQ(recovery.backoff(), milliseconds(80)) << "no frame came through: keeps backing off";
  recovery.onReopened(t0);
  recovery.onFrame(t0);
  EXPECT_EQ(recovery.onFault("gone", true, t0), Step::kReopen);
  EXPECT_EQ(recovery.backoff(), milliseconds(20));
  EXPECT_EQ(recovery.faults(), 8u);
  EXPECT_EQ(recovery.reopens(), 2u);
}

TEST(SourceRecovery, EveryKindKeepsTryingUnlessTheSettingsSayWhenToGiveUp) {
  const LogCapture log;
  SourceRecovery forever("front", {});
  const auto t0 = SourceRecovery::Clock::now();
  for (int k = 0; k < 10'000; ++k) ASSERT_NE(forever.onFault("bad", k % 2 == 0, t0), Step::kGiveUp);

  RecoverySettings settings;
  settings.giveUpAfterFaults = 5;
  SourceRecovery limited("front", settings);
  for (int k = 0; k < 4; ++k) EXPECT_NE(limited.onFault("bad", false, t0), Step::kGiveUp);
  limited.onFrame(t0);  // a frame between: the count starts again
  for (int k = 0; k < 4; ++k) EXPECT_NE(limited.onFault("bad", false, t0), Step::kGiveUp);
  EXPECT_EQ(limited.onFault("bad", true, t0), Step::kGiveUp);
  EXPECT_TRUE(limited.gaveUp());
  EXPECT_THAT(log.lines().back(),
              HasSubstr("camera 'front': 5 faults in a row, giving up on this camera"));
}

TEST(FaultLog, TheFirstFaultInFullThenOneLineAnIntervalThatCountsTheRest) {
  const LogCapture log;
  FaultLog faults("front", milliseconds(10'000));
  const auto t0 = FaultLog::Clock::now();
  // 30 faults a second for 25 s.
  for (int k = 0; k < 750; ++k) {
    faults.fault(fmt::format("camera 'front': corrupt MJPEG frame {}", k),
                 t0 + k * milliseconds(33));
  }
  faults.flush(t0 + milliseconds(25'000));
  const auto lines = log.lines();
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0], "[warning] camera 'front': corrupt MJPEG frame 0");
  EXPECT_EQ(
      lines[1],
      "[warning] camera 'front': 304 more faults in 10.0 s; the last: corrupt MJPEG frame 304");
  EXPECT_THAT(lines[2], HasSubstr("304 more faults in 10.0 s; the last: corrupt MJPEG frame 608"));
  EXPECT_THAT(lines[3], HasSubstr("141 more faults in 4.9 s; the last: corrupt MJPEG frame 749"));
  EXPECT_EQ(faults.linesLogged(), 4u);
  EXPECT_EQ(faults.linesLeftOut(), 747u);
}

std::shared_ptr<testing::FakeV4l2Device::State> mjpegDevice() {
  auto state = std::make_shared<testing::FakeV4l2Device::State>();
  state->modes = {{V4L2_PIX_FMT_MJPEG, kSize}};
  state->picture = [](std::uint64_t frame, cv::Size size) {
    return testing::syntheticPicture(size, static_cast<int>(frame));
  };
  return state;
}

std::unique_ptr<V4l2Source> fakeCamera(
    const std::shared_ptr<testing::FakeV4l2Device::State>& state) {
  V4l2Settings settings;
  settings.device = "/dev/v4l/by-path/fake";
  settings.size = kSize;
  return std::make_unique<V4l2Source>("front", settings,
                                      std::make_unique<testing::FakeV4l2Device>(state));
}

// Takes frames until `count` have come, or the stream ends or stalls for 10 s.
int takeFrames(CameraStream& stream, int count) {
  int frames = 0;
  FrameRef frame;
  while (frames < count && stream.next(frame, milliseconds(10'000)) == CameraStream::Next::kFrame) {
    ++frames;
    frame.reset();
  }
  return frames;
}

TEST(SourceRecovery, ACorruptMjpegStreamLogsItsFirstFaultNotOneLineEach) {
  const LogCapture log;
  const auto state = mjpegDevice();
  state->corruptFrames = 300;  // 10 s of a 30 fps camera
  CameraStream stream("front", fakeCamera(state), 4, fastSettings());
  stream.start();
  ASSERT_EQ(takeFrames(stream, 1), 1);
  stream.stop();
  EXPECT_EQ(stream.stats().faults, 300u);
  EXPECT_EQ(state->opens, 1) << "a corrupt frame is no reason to reopen";
  std::vector<std::string> faultLines;
  for (const auto& line : log.lines()) {
    if (line.find("[warning]") != std::string::npos) faultLines.push_back(line);
  }
  // Before: 300 lines. Now the first, and (the run taking well under 10 s) the count at the end.
  ASSERT_GE(faultLines.size(), 1u);
  EXPECT_LE(faultLines.size(), 2u);
  EXPECT_THAT(faultLines[0], HasSubstr("camera 'front': /dev/v4l/by-path/fake: corrupt MJPEG"));
}

TEST(SourceRecovery, AnUnpluggedCameraIsReopenedWithBackoffThroughTheStream) {
  const LogCapture log;
  const auto state = mjpegDevice();
  state->modes = {{V4L2_PIX_FMT_YUYV, kSize}};
  state->unplugAtFrame = 5;
  state->failedOpens = 3;
  CameraStream stream("front", fakeCamera(state), 4, fastSettings());
  const auto start = std::chrono::steady_clock::now();
  stream.start();
  ASSERT_EQ(takeFrames(stream, 10), 10);
  const auto took = std::chrono::steady_clock::now() - start;
  stream.stop();
  // Lost, then three failed opens: waits of 20, 40, 80 and 80 ms before the four tries.
  EXPECT_GE(took, milliseconds(220));
  EXPECT_EQ(stream.stats().faults, 4u);
  EXPECT_EQ(stream.stats().reopens, 1u);
  // The first fault in full; the rest, and the reopening, counted in one line at the end.
  const auto lines = log.lines();
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_THAT(lines[0], HasSubstr("No such device; reopening"));
  EXPECT_THAT(lines[1], HasSubstr("3 more faults in"));
  EXPECT_THAT(lines[1], HasSubstr(", reopened once; the last: reopening failed"));
}

TEST(SourceRecovery, AGiveUpRuleInTheSettingsEndsTheStream) {
  const LogCapture log;
  RecoverySettings settings = fastSettings();
  settings.giveUpAfterFaults = 10;
  const auto state = mjpegDevice();
  state->corruptFrames = 1'000;
  CameraStream camera("front", fakeCamera(state), 4, settings);
  camera.start();
  EXPECT_EQ(takeFrames(camera, 1), 0);  // ended
  EXPECT_EQ(camera.stats().faults, 10u);
}

// A replay whose middle is damaged: H.264 conceals the errors and delivers the frames. Each such
// frame is shown and counted as a fault; the decoder's own messages do not flood the log.
TEST(SourceRecovery, FramesAReplayDecodesWithErrorsAreCountedAndLoggedOnce) {
  const testing::TempDir dir;
  const auto path = dir / "damaged.mkv";
  {
    render::VideoEncoderSettings video;
    video.path = path;
    video.size = kSize;
    video.crf = 18;
    video.threads = 1;
    video.bitExact = true;
    render::VideoEncoder encoder(video);
    for (int k = 0; k < 60; ++k) {
      encoder.write(testing::syntheticPicture(kSize, k), std::chrono::microseconds(k * 33'333));
    }
    encoder.close();
  }
  const auto size = static_cast<std::streamoff>(std::filesystem::file_size(path));
  {
    std::fstream file(path, std::ios::binary | std::ios::in | std::ios::out);
    cv::Mat bytes(1, 64, CV_8U);
    for (int k = 1; k < 8; ++k) {
      cv::RNG(static_cast<std::uint64_t>(k)).fill(bytes, cv::RNG::UNIFORM, 0, 256);
      file.seekp(size * k / 10);
      file.write(bytes.ptr<char>(), 64);
    }
  }
  const LogCapture log;
  auto source = std::make_unique<FileSource>(
      "front", FileSourceSettings{path, 30.0, false, Pacing::kAsFastAsPossible});
  CameraStream stream("front", std::move(source), 4, fastSettings());
  stream.start();
  const int frames = takeFrames(stream, 1'000);
  stream.stop();
  EXPECT_GT(frames, 30);
  EXPECT_GT(stream.stats().faults, 0u) << "frames decoded with errors are faults";
  std::size_t faultLines = 0;
  for (const auto& line : log.lines()) {
    if (line.find("[warning]") != std::string::npos) ++faultLines;
  }
  EXPECT_GE(faultLines, 1u);
  EXPECT_LE(faultLines, 2u);
}

}  // namespace
}  // namespace surroundd::capture
