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

}  // namespace surroundd::testing
