#pragma once
// What a KMS screen shows: the frame buffer its display controller scans out, read through the
// kernel as the tests' second look at a display output (as x11_test_server.hpp's observer is for
// windows). Reading another client's buffers takes root (DRM_IOCTL_MODE_GETFB2 hands their
// handles to the DRM master or CAP_SYS_ADMIN only): scripts/device-vm.sh runs the tests that take a
// screen over as root in a virtual machine with one, and says so in SURROUNDD_KMS_SCREEN.

#include <cstdint>
#include <filesystem>

#include <opencv2/core.hpp>

namespace surroundd::testing {

// The card whose screen the tests may take over (SURROUNDD_KMS_SCREEN); empty where none is.
std::filesystem::path kmsScreenForTests();

struct Scanout {
  std::uint32_t framebuffer = 0;  // 0: the display controller shows nothing
  cv::Mat picture;                // BGR, the frame buffer's size
};

// The frame buffer on `card`'s first active display controller. Throws std::runtime_error when
// it cannot be read (not root, a format other than 32-bit RGB).
Scanout scanout(const std::filesystem::path& card);

// Where the display outputs show a picture of `picture` size on a screen of `screen` size:
// fitted, keeping its aspect, and centred.
cv::Rect fittedPlace(cv::Size picture, cv::Size screen);

// A screen's picture against what it should show: `expected` in `area`, black around it.
struct ShownAgainst {
  double largestDifference = 0;  // in `area`, in levels
  int litAround = 0;             // levels around `area` that are not 0
};
ShownAgainst compareShown(const cv::Mat& shown, const cv::Mat& expected, const cv::Rect& area);

}  // namespace surroundd::testing
