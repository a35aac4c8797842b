// The `display` output with `present: egl`, through the pipeline on a generated recording: on a
// screen the tests may take over (a virtual machine's: ctest's DisplayOutput.OnAKmsScreen, through
// scripts/device-vm.sh), the renderer opens on the card's GBM device and the screen shows the sets'
// surround views as OpenGL drew them, with no read-back — at the end, a picture that a lossless
// video of the same view holds (the last, unless a flip was still pending), and the snapshot reads
// the last one back. Anywhere: the config's rules for it and a card that cannot be opened.

#include "daemon/outputs/display/display_output.hpp"

#include <atomic>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "daemon/pipeline.hpp"
#include "tests/daemon/config/config_test_support.hpp"
#include "tests/daemon/replay_config.hpp"
#include "tests/support/kms_scanout.hpp"
#include "tests/support/kms_screen_test.hpp"
#include "tests/support/log_capture.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {
namespace {

using ::testing::AllOf;
using ::testing::Contains;
using ::testing::HasSubstr;

OutputConfig eglDisplay(const std::filesystem::path& card) {
  OutputConfig display;
  display.kind = OutputKind::kDisplay;
  display.stream = OutputStream::kSurround;
  display.view = ViewKind::kOrbit;
  display.settings = OutputSettings(
      DisplayOutputSettings{.device = card, .connector = "", .present = ViewPresent::kEgl});
  return display;
}

using DisplayOutputOnAScreen = testing::KmsScreenTest;

TEST_F(DisplayOutputOnAScreen, AnEglDisplayShowsTheSetsViewsAsALosslessVideoOfThemHasThem) {
  const std::filesystem::path& card = card_;
  const testing::TempDir dir;
  OutputConfig video = videoOutputAt(dir.path() / "orbit.mkv", losslessBgr());
  video.stream = OutputStream::kSurround;
  video.view = ViewKind::kOrbit;
  Config config = fixtureReplay("synth_small", {video, eglDisplay(card)});
  config.panorama.cacheDir = dir.path() / "cache";
  const std::atomic<bool> stop{false};
  const testing::LogCapture capture;
  Pipeline pipeline(config);
  const RunSummary summary = pipeline.run(stop);
  const auto log = capture.lines();

  EXPECT_THAT(log, Contains(HasSubstr("render: on the gbm platform of the display output")));
  ASSERT_GT(summary.frameSets, 5U);
  EXPECT_EQ(summary.failedOutputs, 0U);
  EXPECT_THAT(summary.outputs, Contains(::testing::MatchesRegex(fmt::format(
                                   "EGL display .+ on {} \\([0-9]+ frames.*\\)", card.string()))));
  const auto frames = testing::decodeAll(video.path).images;
  ASSERT_EQ(frames.size(), summary.frameSets);
  ASSERT_GT(cv::norm(frames.front(), frames.back(), cv::NORM_INF), 100) << "the eye orbits";

  // The screen keeps showing the last view presented until the pipeline goes.
  const auto shown = testing::scanout(card);
  ASSERT_FALSE(shown.picture.empty());
  const cv::Rect area = testing::fittedPlace(frames.back().size(), shown.picture.size());
  double closest = std::numeric_limits<double>::max();
  std::size_t closestFrame = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    cv::Mat scaled;
    cv::resize(frames[i], scaled, area.size(), 0, 0, cv::INTER_LINEAR);
    if (const double difference = cv::norm(shown.picture(area), scaled, cv::NORM_INF);
        difference < closest) {
      closest = difference;
      closestFrame = i;
    }
  }
  // The GPU's bilinear scaling against OpenCV's (2 levels) of a lossless picture (1).
  EXPECT_LE(closest, 3);
  if (std::ranges::none_of(summary.outputs,
                           [](const std::string& o) { return o.find("not shown") != o.npos; })) {
    EXPECT_EQ(closestFrame, frames.size() - 1) << "every view was shown, the last one last";
  }
  // A snapshot (surroundctl snapshot) reads the display's view back when asked for.
  EXPECT_LE(cv::norm(pipeline.latestPicture(), frames.back(), cv::NORM_INF), 1);
}

TEST(DisplayOutput, AnEglDisplayOnACardThatCannotBeOpenedIsNamed) {
  const Config config = fixtureReplay("synth_small", {eglDisplay("/dev/dri/card97")});
  const testing::LogCapture capture;
  EXPECT_THAT([&] { const Pipeline pipeline(config); },
              ::testing::ThrowsMessage<std::runtime_error>(HasSubstr(
                  "display on /dev/dri/card97: present: egl needs the renderer on this card")));
  EXPECT_THAT(capture.lines(),
              Contains(AllOf(HasSubstr("the display output cannot have the renderer"),
                             HasSubstr("/dev/dri/card97: cannot open"))));
}

TEST_F(ConfigTest, AnEglDisplayShowsTheSurroundViewOnOneCard) {
  expectOneError("{type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "{type: display, present: egl}",
                 {"outputs[1].present", "the display's stream must be surround"});
  expectOneError("{type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "{type: display, stream: surround, present: egl, device: /dev/dri/card0}\n"
                 "  - {type: display, stream: surround, present: egl, device: /dev/dri/card1}",
                 {"outputs[2].device", "which an earlier egl display puts on /dev/dri/card0"});
  expectOneError("{type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "{type: display, stream: surround, present: kms}", {"'picture' 'egl'"});
}

}  // namespace
}  // namespace surroundd::daemon
