// surroundd's rtsp output as a player sees it: FFmpeg connects to a running daemon and gets the
// rendered frames from there to the end. A test program of its own: under ASan, LeakSanitizer
// cannot judge GStreamer's allocations (tests/CMakeLists.txt, GLIB).

#include <csignal>
#include <thread>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "tests/support/child_process.hpp"
#include "tests/support/stream_receiver.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd {
namespace {

std::filesystem::path recording() {
  return std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_small";
}

// The rtsp output: a player (FFmpeg, over TCP) that connects while the daemon runs sees, from then
// on to the end, the pictures of the video file of the same view, each with its capture time.
TEST(RtspEndToEnd, APlayerThatJoinsSeesTheRenderedFramesToTheEnd) {
  const testing::TempDir dir;
  // The recording's rig, each camera looping, so that it runs until it is stopped.
  std::string rig = testing::fileBytes(recording() / "rig.yaml");
  for (const char* camera : {"front", "right", "back", "left"}) {
    const std::string from = fmt::format("source: {{file: {}.mkv}}", camera);
    const std::string to = fmt::format("source: {{file: {}, loop: true}}",
                                       (recording() / (std::string(camera) + ".mkv")).string());
    ASSERT_NE(rig.find(from), std::string::npos) << from;
    rig.replace(rig.find(from), from.size(), to);
  }
  const auto config = dir.write("config.yaml", fmt::format(R"(rig: {{file: {}}}
capture: {{pacing: realtime}}
pipeline: {{threads: 2}}
panorama: {{width_px: 512, height_px: 256, cache_dir: lut-cache}}
render: {{width_px: 320, height_px: 240, view: orbit}}
outputs:
  - {{type: rtsp, stream: surround, listen: "127.0.0.1:0", crf: 18}}
  - {{type: video, stream: surround, path: out/orbit.mkv, crf: 0, pixel_format: yuv444p}}
)",
                                                           dir.write("rig.yaml", rig).string()));
  const auto started = std::chrono::system_clock::now();
  testing::ChildProcess surroundd({SURROUNDD_EXECUTABLE, "--config", config.string()},
                                  dir / "log.txt");
  // Its address, port and all, is in the log once it listens.
  std::string url;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (url.empty() && std::chrono::steady_clock::now() < deadline && surroundd.running()) {
    const std::string log = testing::fileBytes(dir / "log.txt");
    if (const auto at = log.find("RTSP stream: rtsp://"); at != std::string::npos) {
      const auto end = log.find('\n', at);
      if (end != std::string::npos) url = log.substr(at + 13, end - at - 13);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_THAT(url, ::testing::MatchesRegex("rtsp://127\\.0\\.0\\.1:[0-9]+/surround"))
      << surroundd.output();
  testing::StreamReceiver player(bench::StreamViewerSettings{url, "tcp", std::chrono::seconds(10)});
  // It has connected, or failed (its own 10 s timeout at most).
  while (!player.started()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::this_thread::sleep_for(std::chrono::seconds(2));
  surroundd.signal(SIGTERM);
  ASSERT_EQ(surroundd.wait(), 0) << surroundd.output();
  EXPECT_THAT(surroundd.output(), ::testing::ContainsRegex(fmt::format(
                                      "wrote RTSP stream {} \\([0-9]+ frames, 1 viewers\\)", url)));
  const auto file = testing::decodeAll(dir / "out/orbit.mkv").images;
  const auto received = player.pictures();
  ASSERT_TRUE(player.error().empty()) << player.error();
  // Two seconds at the cameras' 30 per second, give or take the start.
  ASSERT_GE(received.size(), 30u);
  ASSERT_LE(received.size(), file.size());
  const std::size_t skipped = file.size() - received.size();
  for (std::size_t k = 0; k < received.size(); ++k) {
    EXPECT_GE(cv::PSNR(received[k].bgr, file[skipped + k]), 32.0) << "picture " << k;
    ASSERT_TRUE(received[k].captured.has_value()) << k;
    EXPECT_GT(*received[k].captured, started) << k;
    EXPECT_LT(*received[k].captured, received[k].decoded) << k;
    if (k > 0) {
      EXPECT_GT(*received[k].captured, *received[k - 1].captured) << k;
    }
  }
}

}  // namespace
}  // namespace surroundd
