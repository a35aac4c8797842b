// The DRM/KMS display output. This machine has no display hardware (and a test must not take over
// a real screen), so what is checked here is that every way of not having a usable display gives
// one clear message naming the device; showing pictures needs a KMS card (vkms works).

#include "render/outputs/drm_display_sink.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "render/render_error.hpp"

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

}  // namespace
}  // namespace surroundd::render
