// The V4L2 source on a real kernel driver: vivid, the kernel's virtual video test driver, whose
// capture devices stream its 75% colour bars like a camera. ctest runs these on a virtual
// machine with four of them, the first and third through the single-planar API and the others
// through the multi-planar one (V4l2Source.OnVividCameras, scripts/device-vm.sh); skipped, with
// a message, where the machine has no vivid device.

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include "capture/frame.hpp"
#include "capture/v4l2_source.hpp"
#include "common/pixel_format.hpp"
#include "tests/support/vivid_cameras.hpp"

namespace surroundd::capture {
namespace {

class VividCameras : public ::testing::Test {
 protected:
  void SetUp() override {
    cameras_ = testing::vividCameras();
    if (cameras_.size() < 4) {
      GTEST_SKIP() << "no four vivid devices here (ctest runs these on a virtual machine's: "
                      "V4l2Source.OnVividCameras)";
    }
  }

  // A frame of the source's held format, read; its picture in BGR.
  static cv::Mat readPicture(V4l2Source& source, Frame& frame) {
    if (frame.image.empty()) {
      frame.format = source.pixelFormat();
      frame.image.create(heldSize(frame.format, source.frameSize()), heldType(frame.format));
    }
    EXPECT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
    cv::Mat bgr;
    heldToBgr(frame.image, frame.format, bgr);
    return bgr;
  }

  std::vector<std::filesystem::path> cameras_;
};

// Each bar's middle, below the text vivid writes at the top, within 12 levels.
void expectBars(const cv::Mat& picture) {
  ASSERT_EQ(picture.size(), cv::Size(640, 360));
  for (std::size_t bar = 0; bar < testing::kVividBars.size(); ++bar) {
    const int x = static_cast<int>((2 * bar + 1) * 640 / 16);
    const cv::Vec3b& shown = picture.at<cv::Vec3b>(300, x);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(shown[c], testing::kVividBars[bar][static_cast<std::size_t>(c)], 12)
          << "bar " << bar << " channel " << c;
    }
  }
}

TEST_F(VividCameras, EachFormatShowsTheColourBarsThroughBothApis) {
  for (std::size_t camera = 0; camera < 2; ++camera) {  // one single-planar, one multi-planar
    for (const V4l2Format format : {V4l2Format::kYuyv, V4l2Format::kUyvy, V4l2Format::kNv12}) {
      SCOPED_TRACE(cameras_[camera].string() + " " + toString(format));
      V4l2Source source("vivid", testing::vividSettings(cameras_[camera], format));
      EXPECT_EQ(source.multiplanar(), camera == 1);
      EXPECT_EQ(source.format(), format);
      Frame frame;
      Timestamp previous{0};
      cv::Mat picture;
      for (int k = 0; k < 3; ++k) {
        picture = readPicture(source, frame);
        EXPECT_GT(frame.timestamp, previous);
        previous = frame.timestamp;
      }
      expectBars(picture);
    }
  }
}

TEST_F(VividCameras, ItsBuffersAreExportedAsDmabufs) {
  for (std::size_t camera = 0; camera < 2; ++camera) {
    SCOPED_TRACE(cameras_[camera].string());
    V4l2Settings settings = testing::vividSettings(cameras_[camera], V4l2Format::kNv12);
    V4l2Source source("vivid", settings);
    // One per buffer: vivid offers NV12 in one buffer on both APIs, which the source takes before
    // NV12M (two).
    ASSERT_EQ(source.dmabufs().size(), static_cast<std::size_t>(settings.buffers));
    for (const int fd : source.dmabufs()) {
      const auto target = std::filesystem::read_symlink("/proc/self/fd/" + std::to_string(fd));
      EXPECT_NE(target.string().find("dmabuf"), std::string::npos) << target;
      // The luma plane at least: the buffer is there to map.
      void* mapped = ::mmap(nullptr, std::size_t{640} * 360, PROT_READ, MAP_SHARED, fd, 0);
      ASSERT_NE(mapped, MAP_FAILED);
      ::munmap(mapped, std::size_t{640} * 360);
    }
  }
}

// The picture where the frame's DMABUF says it is, mapped through the descriptor.
cv::Mat dmabufPicture(const Frame& frame) {
  const DmabufPlanes& planes = frame.dmabuf;
  const std::size_t rows = static_cast<std::size_t>(frame.image.rows);
  const std::size_t bytes = planes.offset[0] + planes.pitch[0] * rows;
  void* mapped = ::mmap(nullptr, bytes, PROT_READ, MAP_SHARED, planes.fd[0], 0);
  if (mapped == MAP_FAILED) return {};
  cv::Mat picture = cv::Mat(frame.image.size(), frame.image.type(),
                            static_cast<std::uint8_t*>(mapped) + planes.offset[0], planes.pitch[0])
                        .clone();
  ::munmap(mapped, bytes);
  return picture;
}

TEST_F(VividCameras, FramesLentItsBuffersAreThemAndTheStreamGoesOn) {
  for (std::size_t camera = 0; camera < 2; ++camera) {
    for (const V4l2Format format : {V4l2Format::kYuyv, V4l2Format::kNv12}) {
      SCOPED_TRACE(cameras_[camera].string() + " " + toString(format));
      V4l2Source source("vivid", testing::vividSettings(cameras_[camera], format));  // 4 buffers
      ASSERT_EQ(source.lendBuffers(), nullptr);
      FramePool pool(6, source.frameSize(), source.pixelFormat());
      std::vector<FrameRef> held;
      Timestamp previous{0};
      const auto read = [&] {
        held.push_back(pool.acquire(std::chrono::milliseconds(0)));
        EXPECT_EQ(source.read(*held.back()), ReadStatus::kFrame) << source.lastError();
        EXPECT_GT(held.back()->timestamp, previous);
        previous = held.back()->timestamp;
      };
      for (int k = 0; k < 2; ++k) {
        read();
        const Frame& lent = *held.back();
        ASSERT_EQ(lent.dmabuf.planes, format == V4l2Format::kNv12 ? 2u : 1u);
        EXPECT_NE(std::ranges::find(source.dmabufs(), lent.dmabuf.fd[0]), source.dmabufs().end());
        EXPECT_EQ(cv::norm(dmabufPicture(lent), lent.image, cv::NORM_INF), 0.0)
            << "the DMABUF holds another picture";
        cv::Mat bgr;
        heldToBgr(lent.image, lent.format, bgr);
        expectBars(bgr);
      }
      // Two lent: the driver keeps two, and the frames read meanwhile are copies.
      for (int k = 0; k < 3; ++k) {
        read();
        EXPECT_EQ(held.back()->dmabuf.planes, 0u);
        held.pop_back();
      }
      held.clear();  // the lent buffers back to the driver
      read();
      EXPECT_GT(held.back()->dmabuf.planes, 0u);
    }
  }
}

TEST_F(VividCameras, FourCamerasStreamAtOnce) {
  std::vector<std::unique_ptr<V4l2Source>> sources;
  for (const auto& camera : cameras_) {
    sources.push_back(
        std::make_unique<V4l2Source>("vivid", testing::vividSettings(camera, V4l2Format::kYuyv)));
  }
  std::vector<Frame> frames(sources.size());
  std::vector<Timestamp> previous(sources.size(), Timestamp{0});
  for (int round = 0; round < 5; ++round) {
    for (std::size_t i = 0; i < sources.size(); ++i) {
      readPicture(*sources[i], frames[i]);
      EXPECT_GT(frames[i].timestamp, previous[i]) << cameras_[i];
      previous[i] = frames[i].timestamp;
    }
  }
}

}  // namespace
}  // namespace surroundd::capture
