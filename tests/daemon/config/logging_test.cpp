// FFmpeg's log goes through the daemon's (daemon/config/logging.hpp): its errors as the daemon's
// error lines, in the daemon's format, and what a hardware encoder tried under `encoder: auto` says
// when it is not there only at debug level, below the one line the encoder writes about it.

#include <algorithm>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/log.h>
}

#include "daemon/config/logging.hpp"
#include "render/outputs/video_encoder.hpp"
#include "tests/support/log_capture.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

// FFmpeg's log routed for one test, and put back to FFmpeg's own printing after it.
class LoggingTest : public ::testing::Test {
 protected:
  LoggingTest() { routeFfmpegLog(); }
  ~LoggingTest() override { av_log_set_callback(av_log_default_callback); }
  LoggingTest(const LoggingTest&) = delete;
  LoggingTest& operator=(const LoggingTest&) = delete;
};

std::vector<std::string> ffmpegLines(const std::vector<std::string>& lines) {
  std::vector<std::string> found;
  std::ranges::copy_if(lines, std::back_inserter(found), [](const std::string& line) {
    return line.find("ffmpeg: ") != std::string::npos;
  });
  return found;
}

TEST_F(LoggingTest, FfmpegsErrorsAreTheDaemonsErrorLinesAndItsChatterStaysOut) {
  const testing::LogCapture log(spdlog::level::trace);
  av_log(nullptr, AV_LOG_ERROR, "the stream is broken at %d\n", 7);
  av_log(nullptr, AV_LOG_WARNING, "a warning FFmpeg gives on every file\n");
  av_log(nullptr, AV_LOG_INFO, "x264's statistics\n");
  EXPECT_THAT(log.lines(), ::testing::ElementsAre("[error] ffmpeg: the stream is broken at 7"));
}

TEST_F(LoggingTest, AHardwareEncoderThatIsNotThereIsSaidOnceNotAsFfmpegsErrors) {
  const testing::TempDir dir;
  render::VideoEncoderSettings settings;
  settings.path = dir / "auto.mp4";
  settings.size = {320, 240};
  settings.encoder = "auto";
  const testing::LogCapture log(spdlog::level::trace);
  std::string name;
  {
    render::VideoEncoder encoder(settings);
    name = encoder.encoderName();
    encoder.write(cv::Mat(settings.size, CV_8UC3, cv::Scalar(40, 90, 160)),
                  std::chrono::milliseconds(0));
    encoder.close();
  }
  if (name != "libx264") GTEST_SKIP() << "this machine has a hardware encoder: " << name;
  const auto lines = log.lines();
  const auto ffmpeg = ffmpegLines(lines);
  for (const auto& line : ffmpeg) EXPECT_THAT(line, StartsWith("[debug] ffmpeg: ")) << line;
  // NVENC is in Debian's FFmpeg; without NVIDIA's driver it says so when it is tried.
  if (avcodec_find_encoder_by_name("h264_nvenc") != nullptr) {
    EXPECT_TRUE(std::ranges::any_of(ffmpeg, [](const std::string& line) {
      return line.find("h264_nvenc") != std::string::npos;
    })) << "no line from the encoders tried";
  }
  EXPECT_EQ(std::ranges::count_if(lines,
                                  [](const std::string& line) {
                                    return line.find("as no hardware encoder opens here") !=
                                           std::string::npos;
                                  }),
            1);
}

}  // namespace
}  // namespace surroundd::daemon
