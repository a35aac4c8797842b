// The DRM/KMS display output: every way of not having a usable display gives one clear message
// naming the device; and, on a screen the tests may take over (a virtual machine's, which ctest
// gives them through scripts/device-vm.sh: DrmDisplaySink.OnAKmsScreen), the screen shows each
// picture where it should, and is given back as it was found. A test must not take over a real
// screen: without SURROUNDD_KMS_SCREEN those are skipped.

#include "render/outputs/drm_display_sink.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "render/render_error.hpp"
#include "tests/support/kms_scanout.hpp"
#include "tests/support/kms_screen_test.hpp"

namespace surroundd::render {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(DrmDisplaySink, AMissingDeviceIsNamed) {
  EXPECT_THAT(
      [] {
        DrmDisplaySink sink({"/dev/dri/card97", ""});
      },
      ThrowsMessage<RenderError>(
          HasSubstr("display /dev/dri/card97: cannot open: No such file or directory")));
}

TEST(DrmDisplaySink, ADeviceThatIsNotAKmsCardIsRefused) {
  EXPECT_THAT(
      [] {
        DrmDisplaySink sink({"/dev/null", ""});
      },
      ThrowsMessage<RenderError>(HasSubstr("display /dev/null: not a KMS display device")));
}

TEST(DrmDisplaySink, WithoutADeviceTheCardsAreSearchedAndTheOutcomeSaid) {
  try {
    const DrmDisplaySink sink({});
    // A machine with a connected screen and no compositor holding it: the mode was set.
    EXPECT_THAT(sink.describe(), HasSubstr("display "));
  } catch (const RenderError& e) {
    EXPECT_THAT(e.what(), ::testing::AnyOf(HasSubstr("no DRM card (/dev/dri/card*)"),
                                           HasSubstr("no connected connector"),
                                           HasSubstr("cannot become DRM master"),
                                           HasSubstr("no card could show the picture")));
  }
}

class DrmDisplaySinkOnAScreen : public testing::KmsScreenTest {
 protected:
  static PictureTime at(int frame) { return PictureTime(std::chrono::milliseconds(frame * 33)); }
};

TEST_F(DrmDisplaySinkOnAScreen, ShowsEachPictureCentredAndFittedToTheMode) {
  DrmDisplaySink sink({card_, ""});
  const cv::Size mode = testing::scanout(card_).picture.size();
  ASSERT_FALSE(mode.empty()) << "the sink set no mode";

  // As wide as the mode and half as high: shown as it is, between black bars.
  cv::Mat wide(mode.height / 2, mode.width, CV_8UC3);
  cv::randu(wide, 0, 256);
  sink.consume(wide, at(0));
  sink.finish(wide, at(0).stream);
  const cv::Rect middle(0, (mode.height - wide.rows) / 2, wide.cols, wide.rows);
  expectShown(wide, middle, 0);
  const std::uint32_t first = testing::scanout(card_).framebuffer;

  // Half that size: doubled to the same place, on the other buffer.
  cv::Mat small(wide.rows / 2, wide.cols / 2, CV_8UC3);
  cv::randu(small, 0, 256);
  sink.consume(small, at(1));
  sink.finish(small, at(1).stream);
  cv::Mat doubled;
  cv::resize(small, doubled, middle.size(), 0, 0, cv::INTER_LINEAR);
  expectShown(doubled, middle, 1);
  EXPECT_NE(testing::scanout(card_).framebuffer, first) << "no page flip";
  EXPECT_THAT(sink.describe(), ::testing::MatchesRegex(
                                   "display .+-[0-9]+ [0-9]+x[0-9]+@[0-9]+ on .+ \\(2 frames\\)"));
}

TEST_F(DrmDisplaySinkOnAScreen, GivesTheScreenBackAsItFoundIt) {
  const auto before = testing::scanout(card_);
  {
    DrmDisplaySink sink({card_, ""});
    const cv::Mat grey(480, 640, CV_8UC3, cv::Scalar::all(128));
    sink.consume(grey, at(0));
    sink.finish(grey, at(0).stream);
    ASSERT_NE(testing::scanout(card_).framebuffer, before.framebuffer);
  }
  const auto after = testing::scanout(card_);
  EXPECT_EQ(after.framebuffer, before.framebuffer);
  if (!before.picture.empty()) {
    EXPECT_EQ(cv::norm(after.picture, before.picture, cv::NORM_INF), 0);
  }
}

TEST_F(DrmDisplaySinkOnAScreen, AScreenAnotherProcessDrivesIsRefused) {
  const DrmDisplaySink first({card_, ""});
  EXPECT_THAT(
      [this] {
        DrmDisplaySink second({card_, ""});
      },
      ThrowsMessage<RenderError>(HasSubstr("cannot become DRM master")));
}

TEST_F(DrmDisplaySinkOnAScreen, AConnectorThatIsNotThereIsNamedWithThoseThatAre) {
  EXPECT_THAT(
      [this] {
        DrmDisplaySink sink({card_, "HDMI-A-9"});
      },
      ThrowsMessage<RenderError>(::testing::MatchesRegex(
          ".*no connected connector 'HDMI-A-9' \\(found: .+ connected.*\\)")));
}

}  // namespace
}  // namespace surroundd::render
