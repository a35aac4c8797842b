// The V4L2 source on a real kernel device: a v4l2loopback node (modprobe v4l2loopback) fed YUYV
// frames by this test through the device's output side. Skipped, with a message, where the
// machine has no loopback device.

#include <atomic>
#include <filesystem>
#include <fstream>
#include <thread>

#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include "capture/v4l2_source.hpp"
#include "tests/capture/fake_v4l2_device.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::capture {
namespace {

// The first /dev/videoN whose name says it is a loopback device, or empty.
std::filesystem::path loopbackDevice() {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/sys/class/video4linux", ec)) {
    std::ifstream nameFile(entry.path() / "name");
    std::string name;
    std::getline(nameFile, name);
    if (name.find("Dummy") != std::string::npos || name.find("oopback") != std::string::npos) {
      return std::filesystem::path("/dev") / entry.path().filename();
    }
  }
  return {};
}

TEST(V4l2Loopback, FramesWrittenToALoopbackDeviceArriveAsBgr) {
  const std::filesystem::path device = loopbackDevice();
  if (device.empty()) {
    GTEST_SKIP() << "no v4l2loopback device (sudo modprobe v4l2loopback); the fake-device tests "
                    "cover the same code";
  }
  const cv::Size size(320, 240);
  const int writer =
      ::open(device.c_str(), O_RDWR | O_CLOEXEC);  // NOLINT(cppcoreguidelines-pro-type-vararg)
  ASSERT_GE(writer, 0) << device;
  v4l2_format format{};
  format.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  format.fmt.pix.width = static_cast<std::uint32_t>(size.width);
  format.fmt.pix.height = static_cast<std::uint32_t>(size.height);
  format.fmt.pix.pixelformat = V4L2_PIX_FMT_YUYV;
  format.fmt.pix.field = V4L2_FIELD_NONE;
  format.fmt.pix.bytesperline = static_cast<std::uint32_t>(size.width * 2);
  format.fmt.pix.sizeimage = static_cast<std::uint32_t>(size.area() * 2);
  ASSERT_EQ(::ioctl(writer, VIDIOC_S_FMT, &format),
            0);  // NOLINT(cppcoreguidelines-pro-type-vararg)

  std::atomic<bool> done{false};
  std::thread feed([&] {
    for (int k = 0; !done; ++k) {
      const auto bytes =
          surroundd::testing::packedYuv(surroundd::testing::syntheticPicture(size, k % 8), true);
      if (::write(writer, bytes.data(), bytes.size()) < 0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(33));
    }
  });
  V4l2Settings settings;
  settings.device = device;
  settings.size = size;
  settings.format = V4l2Format::kYuyv;
  settings.timeout = std::chrono::milliseconds(2000);
  try {
    V4l2Source source("loopback", settings);
    Frame frame;
    frame.image.create(size, CV_8UC3);
    Timestamp previous{0};
    for (int k = 0; k < 5; ++k) {
      ASSERT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
      EXPECT_GT(frame.timestamp, previous);
      previous = frame.timestamp;
      double best = 0;  // which of the eight pictures it is depends on when reading started
      for (int picture = 0; picture < 8; ++picture) {
        best = std::max(best,
                        cv::PSNR(frame.image, surroundd::testing::syntheticPicture(size, picture)));
      }
      EXPECT_GE(best, 28.0);
    }
  } catch (const CaptureError& e) {
    ADD_FAILURE() << e.what();
  }
  done = true;
  feed.join();
  ::close(writer);
}

}  // namespace
}  // namespace surroundd::capture
