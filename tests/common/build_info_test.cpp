// What a build says of its optional parts: how to build one in, from the one table CMake keeps
// (cmake/OptionalParts.cmake), which every refusal of a left-out part quotes.

#include "common/build_info.hpp"

#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace surroundd {
namespace {

using ::testing::HasSubstr;

TEST(BuildInfo, SaysHowToBuildInEachOptionalPart) {
  EXPECT_EQ(howToBuildIn("HTTP"),
            "configure with -DSURROUNDD_WITH_HTTP=ON (needs libmicrohttpd-dev libturbojpeg0-dev)");
  EXPECT_THAT(howToBuildIn("LIBCAMERA"), HasSubstr("-DSURROUNDD_WITH_LIBCAMERA=ON"));
  EXPECT_THAT(howToBuildIn("RTSP"), HasSubstr("libgstrtspserver-1.0-dev"));
  EXPECT_THROW((void)howToBuildIn("HOLOGRAM"), std::logic_error);
}

TEST(BuildInfo, VersionNamesTheProgramAndThePartsInAndOut) {
  const std::string text = versionText("surroundd");
  EXPECT_THAT(text, ::testing::StartsWith("surroundd "));
  EXPECT_THAT(text, HasSubstr("\nbuilt with: "));
  EXPECT_THAT(text, HasSubstr("\nwithout: "));
}

}  // namespace
}  // namespace surroundd
