// The libcamera source where no camera answers to the name: one message naming the camera and
// listing what libcamera found (on a machine with cameras, their ids). Built without libcamera,
// the message says so instead.

#include "capture/libcamera_source.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace surroundd::capture {
namespace {

using ::testing::HasSubstr;

TEST(LibcameraSource, ACameraThatIsNotThereIsNamedWithWhatWasFound) {
  LibcameraSettings settings;
  settings.camera = "surroundd-test-no-such-camera";
  settings.size = {640, 480};
  try {
    LibcameraSource source("front", settings);
    FAIL() << "a camera that does not exist was opened";
  } catch (const CaptureError& e) {
    if (libcameraAvailable()) {
      EXPECT_THAT(e.what(), HasSubstr("camera 'front': no libcamera camera matches "
                                      "'surroundd-test-no-such-camera' (found: "));
    } else {
      EXPECT_THAT(e.what(), HasSubstr("built without libcamera"));
    }
  }
}

}  // namespace
}  // namespace surroundd::capture
