// The `window` output with `present: egl`, through the pipeline on a generated recording and an
// Xvfb server of the test's own: the renderer opens on the window's X server and the window shows
// each set's surround view as OpenGL drew it, with no read-back — at the end, exactly the last
// picture that a lossless video of the same view holds, and what a snapshot reads back. And the
// config's rules for it.

#include "daemon/outputs/window/window_output.hpp"

#include <atomic>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "daemon/pipeline.hpp"
#include "tests/daemon/config/config_test_support.hpp"
#include "tests/daemon/replay_config.hpp"
#include "tests/support/log_capture.hpp"
#include "tests/support/test_support.hpp"
#include "tests/support/x11_test_server.hpp"

namespace surroundd::daemon {
namespace {

using ::testing::AllOf;
using ::testing::Contains;
using ::testing::HasSubstr;

TEST(WindowOutput, AnEglWindowShowsEachSetsViewAsALosslessVideoOfItHasIt) {
  const testing::XvfbServer server;
  const testing::TempDir dir;
  OutputConfig video = videoOutputAt(dir.path() / "orbit.mkv", losslessBgr());
  video.stream = OutputStream::kSurround;
  video.view = ViewKind::kOrbit;
  OutputConfig window;
  window.kind = OutputKind::kWindow;
  window.stream = OutputStream::kSurround;
  window.view = ViewKind::kOrbit;
  window.settings = OutputSettings(WindowOutputSettings{
      .display = server.display(), .title = "surroundd egl", .present = ViewPresent::kEgl});
  const Config config = fixtureReplay("synth_small", {video, window});
  const testing::X11Observer observer(server.display());
  const std::atomic<bool> stop{false};
  RunSummary summary;
  std::vector<std::string> log;
  const testing::LogCapture capture;
  Pipeline pipeline(config);
  summary = pipeline.run(stop);
  log = capture.lines();

  EXPECT_THAT(log, Contains(HasSubstr("render: on the x11 platform of the window output")));
  EXPECT_THAT(log, Contains(HasSubstr("render: x11: llvmpipe")));
  EXPECT_THAT(log, Contains(HasSubstr("present: egl on a renderer that runs on the CPU")));
  ASSERT_GT(summary.frameSets, 5U);
  EXPECT_EQ(summary.failedOutputs, 0U);
  EXPECT_THAT(summary.outputs, Contains(fmt::format("EGL window on {} ({} frames)",
                                                    server.display(), summary.frameSets)));
  // The window stays until the pipeline goes, showing the last set's view.
  const unsigned long shown = observer.windowTitled("surroundd egl");
  ASSERT_NE(shown, 0U);
  const auto frames = testing::decodeAll(video.path).images;
  ASSERT_EQ(frames.size(), summary.frameSets);
  EXPECT_LE(cv::norm(observer.contents(shown), frames.back(), cv::NORM_INF), 1);
  EXPECT_GT(cv::norm(frames.front(), frames.back(), cv::NORM_INF), 100) << "the eye orbits";
  // A snapshot (surroundctl snapshot) reads the window's view back when asked for.
  EXPECT_LE(cv::norm(pipeline.latestPicture(), frames.back(), cv::NORM_INF), 1);
}

TEST(WindowOutput, AnEglWindowOnAServerThatCannotBeReachedIsNamed) {
  OutputConfig window;
  window.kind = OutputKind::kWindow;
  window.stream = OutputStream::kSurround;
  window.settings = OutputSettings(
      WindowOutputSettings{.display = ":97", .title = "surroundd", .present = ViewPresent::kEgl});
  const Config config = fixtureReplay("synth_small", {window});
  const testing::LogCapture capture;
  EXPECT_THAT([&] { const Pipeline pipeline(config); },
              ::testing::ThrowsMessage<std::runtime_error>(
                  HasSubstr("window on :97: present: egl needs the renderer on this X server")));
  EXPECT_THAT(capture.lines(),
              Contains(AllOf(HasSubstr("the window output cannot have the renderer"),
                             HasSubstr("cannot open display ':97'"))));
}

TEST_F(ConfigTest, AnEglWindowShowsTheSurroundViewOnOneXServer) {
  expectOneError("{type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "{type: window, present: egl}",
                 {"outputs[1].present", "the window's stream must be surround"});
  expectOneError("{type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "{type: window, stream: surround, present: egl, display: \":1\"}\n"
                 "  - {type: window, stream: surround, present: egl, display: \":2\"}",
                 {"outputs[2].display", "which an earlier egl window puts on ':1'"});
  expectOneError("{type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "{type: window, stream: surround, present: gpu}", {"'picture' 'egl'"});
}

}  // namespace
}  // namespace surroundd::daemon
