// The V4L2 source against an in-process fake device (tests/capture/fake_v4l2_device.hpp) and the
// real kernel: format, size and rate negotiation, every pixel format into BGR, controls, and the
// faults a live camera has (a stall, unplugged and plugged back, a corrupt MJPEG frame).

#include "capture/v4l2_source.hpp"

#include <functional>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/capture/fake_v4l2_device.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::capture {
namespace {

using testing::FakeV4l2Device;
using ::testing::HasSubstr;

const cv::Size kSize(320, 240);

std::shared_ptr<FakeV4l2Device::State> deviceOffering(std::vector<FakeV4l2Device::Mode> modes) {
  auto state = std::make_shared<FakeV4l2Device::State>();
  state->modes = std::move(modes);
  state->picture = [](std::uint64_t frame, cv::Size size) {
    return surroundd::testing::syntheticPicture(size, static_cast<int>(frame));
  };
  v4l2_queryctrl gain{};
  gain.id = V4L2_CID_GAIN;
  gain.minimum = 0;
  gain.maximum = 255;
  state->controls.push_back(gain);
  return state;
}

V4l2Settings settingsFor(cv::Size size = kSize) {
  V4l2Settings settings;
  settings.device = "/dev/v4l/by-path/fake-video-index0";
  settings.size = size;
  settings.firstBackoff = std::chrono::milliseconds(20);
  settings.maxBackoff = std::chrono::milliseconds(80);
  return settings;
}

V4l2Source sourceOn(const std::shared_ptr<FakeV4l2Device::State>& state,
                    V4l2Settings settings = settingsFor()) {
  return V4l2Source("front", std::move(settings), std::make_unique<FakeV4l2Device>(state));
}

// The message of the CaptureError that opening throws; a test failure if it throws none.
std::string errorOpening(const std::function<void()>& open) {
  try {
    open();
  } catch (const CaptureError& e) {
    return e.what();
  }
  ADD_FAILURE() << "opened without an error";
  return {};
}

Frame frameOf(cv::Size size) {
  Frame frame;
  frame.image.create(size, CV_8UC3);
  return frame;
}

TEST(V4l2Source, DeliversEveryPixelFormatAsBgrWithTheDriversTimestamps) {
  for (const auto& [fourcc, format] : {std::pair{V4L2_PIX_FMT_YUYV, V4l2Format::kYuyv},
                                       std::pair{V4L2_PIX_FMT_UYVY, V4l2Format::kUyvy},
                                       std::pair{V4L2_PIX_FMT_NV12, V4l2Format::kNv12},
                                       std::pair{V4L2_PIX_FMT_MJPEG, V4l2Format::kMjpeg}}) {
    SCOPED_TRACE(toString(format));
    const auto state = deviceOffering({{fourcc, {640, 480}}, {fourcc, kSize}});
    V4l2Source source = sourceOn(state);
    EXPECT_EQ(source.format(), format);
    EXPECT_EQ(source.frameSize(), kSize);
    EXPECT_EQ(source.nominalPeriod(), std::chrono::nanoseconds(33'333'333));
    Frame frame = frameOf(kSize);
    const uchar* buffer = frame.image.data;
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
      EXPECT_GE(cv::PSNR(frame.image, surroundd::testing::syntheticPicture(kSize, k)), 28.0)
          << "frame " << k;
      EXPECT_EQ(frame.timestamp, std::chrono::microseconds(1'000'000 + k * 33'333));
    }
    EXPECT_EQ(frame.image.data, buffer) << "the frame's image was reallocated";
  }
}

TEST(V4l2Source, AutoTakesTheFirstOfYuyvUyvyNv12MjpegThatTheDeviceOffers) {
  const auto state = deviceOffering({{V4L2_PIX_FMT_MJPEG, kSize}, {V4L2_PIX_FMT_NV12, kSize}});
  EXPECT_EQ(sourceOn(state).format(), V4l2Format::kNv12);
  V4l2Settings mjpeg = settingsFor();
  mjpeg.format = V4l2Format::kMjpeg;
  EXPECT_EQ(sourceOn(state, mjpeg).format(), V4l2Format::kMjpeg);
}

TEST(V4l2Source, ARequestTheDeviceCannotMeetSaysWhatItOffers) {
  const auto state = deviceOffering({{V4L2_PIX_FMT_YUYV, {640, 480}},
                                     {V4L2_PIX_FMT_YUYV, kSize},
                                     {V4L2_PIX_FMT_MJPEG, {1280, 720}}});
  EXPECT_THAT(errorOpening([&] {
                sourceOn(state, settingsFor({1920, 1080}));
              }),
              HasSubstr("camera 'front': /dev/v4l/by-path/fake-video-index0: does not offer auto "
                        "1920x1080 (it offers: YUYV 640x480, 320x240; MJPG 1280x720)"));
  V4l2Settings nv12 = settingsFor();
  nv12.format = V4l2Format::kNv12;
  EXPECT_THROW(sourceOn(state, nv12), CaptureError);
}

TEST(V4l2Source, ControlsAreSetWithinTheirRangesAndRefusedOtherwise) {
  const auto state = deviceOffering({{V4L2_PIX_FMT_YUYV, kSize}});
  V4l2Settings settings = settingsFor();
  settings.controls = {{"gain", 40}};
  sourceOn(state, settings);
  ASSERT_EQ(state->controlsSet.size(), 1u);
  EXPECT_EQ(state->controlsSet[0].id, static_cast<std::uint32_t>(V4L2_CID_GAIN));
  EXPECT_EQ(state->controlsSet[0].value, 40);
  for (const auto& [control, message] :
       {std::pair{V4l2Control{"gain", 300}, "control 'gain' takes 0 to 255, got 300"},
        std::pair{V4l2Control{"exposure_absolute", 10}, "has no control 'exposure_absolute'"},
        std::pair{V4l2Control{"shutter", 1}, "unknown control 'shutter'"}}) {
    settings.controls = {control};
    EXPECT_THAT(errorOpening([&] { sourceOn(state, settings); }), HasSubstr(message));
  }
}

TEST(V4l2Source, AStallMarksTheCameraLostAndReopensIt) {
  const auto state = deviceOffering({{V4L2_PIX_FMT_YUYV, kSize}});
  V4l2Source source = sourceOn(state);
  Frame frame = frameOf(kSize);
  ASSERT_EQ(source.read(frame), ReadStatus::kFrame);
  state->stalledPolls = 1;
  EXPECT_EQ(source.read(frame), ReadStatus::kFault);
  EXPECT_THAT(source.lastError(), HasSubstr("no frame within 500 ms; reopening"));
  EXPECT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
  EXPECT_EQ(source.reopened(), 1u);
  EXPECT_EQ(state->opens, 2);
}

TEST(V4l2Source, UnpluggedMidStreamItRetriesWithBackoffAndResumesWhenBack) {
  const auto state = deviceOffering({{V4L2_PIX_FMT_YUYV, kSize}});
  V4l2Source source = sourceOn(state);
  Frame frame = frameOf(kSize);
  ASSERT_EQ(source.read(frame), ReadStatus::kFrame);
  state->plugged = false;
  EXPECT_EQ(source.read(frame), ReadStatus::kFault);
  EXPECT_THAT(source.lastError(), HasSubstr("No such device; reopening"));
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(source.read(frame), ReadStatus::kFault);
    EXPECT_THAT(source.lastError(), HasSubstr("reopening failed"));
  }
  // Waits of 20, 40 and 80 ms before the three tries.
  EXPECT_GE(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(140));
  state->plugged = true;
  ASSERT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
  EXPECT_EQ(source.reopened(), 1u);
  EXPECT_GE(cv::PSNR(frame.image, surroundd::testing::syntheticPicture(
                                      kSize, static_cast<int>(state->produced - 1))),
            28.0);
}

TEST(V4l2Source, ACorruptMjpegFrameIsAFaultAndTheStreamGoesOn) {
  const auto state = deviceOffering({{V4L2_PIX_FMT_MJPEG, kSize}});
  V4l2Source source = sourceOn(state);
  Frame frame = frameOf(kSize);
  ASSERT_EQ(source.read(frame), ReadStatus::kFrame);
  state->corruptNext = true;
  EXPECT_EQ(source.read(frame), ReadStatus::kFault);
  EXPECT_THAT(source.lastError(), HasSubstr("corrupt MJPEG frame"));
  EXPECT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
  EXPECT_EQ(state->opens, 1);  // not reopened
}

TEST(V4l2Source, ExportsItsBuffersAsDmabufWhereTheDriverCan) {
  const auto state = deviceOffering({{V4L2_PIX_FMT_YUYV, kSize}});
  EXPECT_TRUE(sourceOn(state).dmabufs().empty());
  state->exportsDmabuf = true;
  V4l2Source source = sourceOn(state);
  ASSERT_EQ(source.dmabufs().size(), 4u);
  for (const int fd : source.dmabufs()) EXPECT_GE(fd, 0);
}

TEST(V4l2Source, TheKernelPathSaysWhatIsWrongWithTheNode) {
  for (const auto& [device, message] :
       {std::pair{"/dev/v4l/by-id/no-such-camera",
                  "camera 'left': /dev/v4l/by-id/no-such-camera: cannot open: No such file or "
                  "directory"},
        std::pair{"/dev/null", "camera 'left': /dev/null: not a V4L2 device"}}) {
    V4l2Settings settings = settingsFor();
    settings.device = device;
    EXPECT_THAT(errorOpening([&] { V4l2Source("left", settings); }), HasSubstr(message));
  }
}

}  // namespace
}  // namespace surroundd::capture
