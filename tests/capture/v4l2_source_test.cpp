// The V4L2 source against an in-process fake device (tests/capture/fake_v4l2_device.hpp) and the
// real kernel: format, size and rate negotiation, every pixel format into BGR, controls, and the
// faults a live camera has (a stall, unplugged and plugged back, a corrupt MJPEG frame).

#include "capture/v4l2_source.hpp"

#include <filesystem>
#include <fstream>
#include <functional>
#include <tuple>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "capture/camera_stream.hpp"
#include "capture/v4l2_probe.hpp"
#include "tests/capture/fake_v4l2_device.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::capture {
namespace {

using testing::FakeV4l2Device;
using ::testing::HasSubstr;

// NOLINTNEXTLINE(cert-err58-cpp): cv::Size stores two ints; its constructor throws nothing.
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

// A frame as the source's pool would make it: its picture held in the source's format.
Frame frameOf(const V4l2Source& source) {
  Frame frame;
  frame.format = source.pixelFormat();
  frame.image.create(heldSize(frame.format, source.frameSize()), heldType(frame.format));
  return frame;
}

cv::Mat bgrOf(const Frame& frame) {
  cv::Mat bgr;
  heldToBgr(frame.image, frame.format, bgr);
  return bgr;
}

// YUYV, UYVY and NV12 are held as the camera gave them; the others are converted to BGR.
PixelFormat heldAs(V4l2Format format) {
  if (format == V4l2Format::kYuyv) return PixelFormat::kYuyv;
  if (format == V4l2Format::kUyvy) return PixelFormat::kUyvy;
  if (format == V4l2Format::kNv12) return PixelFormat::kNv12;
  return PixelFormat::kBgr;
}

TEST(V4l2Source, DeliversEveryPixelFormatWithTheDriversTimestamps) {
  for (const auto& [fourcc, format] : {std::pair{V4L2_PIX_FMT_YUYV, V4l2Format::kYuyv},
                                       std::pair{V4L2_PIX_FMT_UYVY, V4l2Format::kUyvy},
                                       std::pair{V4L2_PIX_FMT_NV12, V4l2Format::kNv12},
                                       std::pair{V4L2_PIX_FMT_MJPEG, V4l2Format::kMjpeg}}) {
    SCOPED_TRACE(toString(format));
    const auto state = deviceOffering({{fourcc, {640, 480}}, {fourcc, kSize}});
    V4l2Source source = sourceOn(state);
    EXPECT_EQ(source.format(), format);
    EXPECT_EQ(source.pixelFormat(), heldAs(format));
    EXPECT_EQ(source.frameSize(), kSize);
    EXPECT_EQ(source.nominalPeriod(), std::chrono::nanoseconds(33'333'333));
    Frame frame = frameOf(source);
    const uchar* buffer = frame.image.data;
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
      EXPECT_GE(cv::PSNR(bgrOf(frame), surroundd::testing::syntheticPicture(kSize, k)), 28.0)
          << "frame " << k;
      EXPECT_EQ(frame.timestamp, std::chrono::microseconds(1'000'000 + k * 33'333));
    }
    EXPECT_EQ(frame.image.data, buffer) << "the frame's image was reallocated";
  }
}

// i.MX, Rockchip and TI capture drivers speak only the multi-planar API: one-plane formats through
// it, and NV12 as NV12M (luma and chroma in two buffers), lines padded to the driver's stride.
TEST(V4l2Source, AMultiPlanarOnlyDeviceDeliversEveryFormatWithItsStride) {
  for (const auto& [fourcc, format] : {std::pair{V4L2_PIX_FMT_YUYV, V4l2Format::kYuyv},
                                       std::pair{V4L2_PIX_FMT_UYVY, V4l2Format::kUyvy},
                                       std::pair{V4L2_PIX_FMT_NV12, V4l2Format::kNv12},
                                       std::pair{V4L2_PIX_FMT_NV12M, V4l2Format::kNv12},
                                       std::pair{V4L2_PIX_FMT_MJPEG, V4l2Format::kMjpeg}}) {
    SCOPED_TRACE(testing::fourccName(fourcc));
    const auto state = deviceOffering({{fourcc, {640, 480}}, {fourcc, kSize}});
    state->multiplanar = true;
    state->linePadding = 64;
    state->exportsDmabuf = true;
    V4l2Source source = sourceOn(state);
    EXPECT_TRUE(source.multiplanar());
    EXPECT_EQ(source.format(), format);
    EXPECT_EQ(source.pixelFormat(), heldAs(format));
    EXPECT_EQ(source.nominalPeriod(), std::chrono::nanoseconds(33'333'333));
    // One DMABUF per plane of each of the 4 buffers.
    EXPECT_EQ(source.dmabufs().size(), fourcc == V4L2_PIX_FMT_NV12M ? 8u : 4u);
    Frame frame = frameOf(source);
    for (int k = 0; k < 6; ++k) {  // past the 4 buffers: each is requeued and used again
      ASSERT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
      EXPECT_GE(cv::PSNR(bgrOf(frame), surroundd::testing::syntheticPicture(kSize, k)), 28.0)
          << "frame " << k;
      EXPECT_EQ(frame.timestamp, std::chrono::microseconds(1'000'000 + k * 33'333));
    }
  }
}

TEST(V4l2Source, AMultiPlanarDeviceIsLostAndReopenedLikeAnyOther) {
  const auto state = deviceOffering({{V4L2_PIX_FMT_NV12M, kSize}});
  state->multiplanar = true;
  V4l2Source source = sourceOn(state);
  Frame frame = frameOf(source);
  ASSERT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
  state->stalledPolls = 1;
  EXPECT_EQ(source.read(frame), ReadStatus::kLost);
  source.reopen();
  ASSERT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
  EXPECT_EQ(state->opens, 2);
}

TEST(V4l2Source, AMultiPlanarDeviceSaysSoWhenItCannotMeetTheRequest) {
  const auto state = deviceOffering({{V4L2_PIX_FMT_NV12M, {640, 480}}});
  state->multiplanar = true;
  EXPECT_THAT(errorOpening([&] { sourceOn(state); }),
              HasSubstr("does not offer auto 320x240 (it offers, multi-planar: NM12 640x480)"));
  // NV12M exists only in the multi-planar API; a single-planar device offering it is not used.
  const auto single = deviceOffering({{V4L2_PIX_FMT_NV12M, kSize}});
  EXPECT_THROW(sourceOn(single), CaptureError);
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

// Issue 50: what --list-cameras and --check-config read of a device, without streaming: its
// formats, sizes and each size's rates, and the same choice the source makes.
TEST(V4l2Probe, ReadsFormatsSizesAndRatesAndChoosesAsTheSourceDoes) {
  const auto state =
      deviceOffering({{V4L2_PIX_FMT_MJPEG, {1280, 720}}, {V4L2_PIX_FMT_NV12, kSize}});
  state->periodUs = 40'000;
  FakeV4l2Device device(state);
  const V4l2Probe probe =
      probeV4l2("/dev/video7", "camera 'front': /dev/video7", device, FrameRates::kListed);
  EXPECT_TRUE(probe.capture);
  EXPECT_EQ(probe.card, "Fake camera");
  EXPECT_EQ(describe(probe.offers, FrameRates::kListed),
            "MJPG 1280x720 (25 fps); NV12 320x240 (25 fps)")
      << "offers as the fake device lists them";
  // What a source's opening asks: the formats and sizes, no rates.
  FakeV4l2Device again(state);
  const V4l2Probe opening = probeV4l2("/dev/video7", "camera 'front': /dev/video7", again);
  ASSERT_EQ(opening.offers.size(), 2U);
  EXPECT_TRUE(opening.offers[0].rates.empty());
  EXPECT_EQ(describe(opening.offers), "MJPG 1280x720; NV12 320x240");
  EXPECT_EQ(fourccText(V4L2_PIX_FMT_Y10), "Y10");
  EXPECT_EQ(fourccText(V4L2_PIX_FMT_Y16_BE), "Y16-BE");
  EXPECT_EQ(chooseV4l2Format(probe, settingsFor())->format, V4l2Format::kNv12);
  EXPECT_EQ(chooseV4l2Format(probe, settingsFor({640, 480})), nullptr);
  EXPECT_THAT(notOffered(probe, settingsFor({640, 480})),
              HasSubstr("does not offer auto 640x480 (it offers: MJPG 1280x720; "));
}

TEST(V4l2Probe, NodesComeInNumberOrderWithTheirPersistentNames) {
  const testing::TempDir dev;
  for (const char* node : {"video10", "video2", "video0", "videox", "media0"}) {
    std::ofstream(dev / node) << "";
  }
  std::filesystem::create_directories(dev / "v4l/by-path");
  std::filesystem::create_directories(dev / "v4l/by-id");
  std::filesystem::create_symlink("../../video2",
                                  dev / "v4l/by-path/pci-0000:00:14.0-video-index0");
  std::filesystem::create_symlink("../../video2", dev / "v4l/by-id/usb-Cam-video-index0");
  const auto nodes = v4l2Nodes(dev.path());
  ASSERT_EQ(nodes.size(), 3U);
  EXPECT_EQ(nodes[0].path.filename(), "video0");
  EXPECT_EQ(nodes[1].path.filename(), "video2");
  EXPECT_EQ(nodes[2].path.filename(), "video10");
  ASSERT_EQ(nodes[1].persistentNames.size(), 2U);
  EXPECT_EQ(nodes[1].persistentNames[0], dev / "v4l/by-path/pci-0000:00:14.0-video-index0");
  EXPECT_EQ(nodes[1].persistentNames[1], dev / "v4l/by-id/usb-Cam-video-index0");
  EXPECT_TRUE(nodes[0].persistentNames.empty());
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

TEST(V4l2Source, AStallIsALostDeviceThatReopenStartsAgain) {
  const auto state = deviceOffering({{V4L2_PIX_FMT_YUYV, kSize}});
  V4l2Source source = sourceOn(state);
  Frame frame = frameOf(source);
  ASSERT_EQ(source.read(frame), ReadStatus::kFrame);
  state->stalledPolls = 1;
  EXPECT_EQ(source.read(frame), ReadStatus::kLost);
  EXPECT_THAT(source.lastError(), HasSubstr("no frame within 500 ms; reopening"));
  EXPECT_EQ(source.read(frame), ReadStatus::kLost) << "read again without reopening";
  source.reopen();
  EXPECT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
  EXPECT_EQ(source.reopened(), 1u);
  EXPECT_EQ(state->opens, 2);
}

TEST(V4l2Source, UnpluggedItIsLostAndReopensOnceBack) {
  const auto state = deviceOffering({{V4L2_PIX_FMT_YUYV, kSize}});
  V4l2Source source = sourceOn(state);
  Frame frame = frameOf(source);
  ASSERT_EQ(source.read(frame), ReadStatus::kFrame);
  state->plugged = false;
  EXPECT_EQ(source.read(frame), ReadStatus::kLost);
  EXPECT_THAT(source.lastError(), HasSubstr("No such device; reopening"));
  EXPECT_THAT(errorOpening([&] { source.reopen(); }),
              HasSubstr("camera 'front': /dev/v4l/by-path/fake-video-index0: cannot open"));
  state->plugged = true;
  source.reopen();
  ASSERT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
  EXPECT_EQ(source.reopened(), 1u);
  EXPECT_GE(cv::PSNR(bgrOf(frame), surroundd::testing::syntheticPicture(
                                       kSize, static_cast<int>(state->produced - 1))),
            28.0);
}

TEST(V4l2Source, ACorruptMjpegFrameIsAFaultAndTheStreamGoesOn) {
  const auto state = deviceOffering({{V4L2_PIX_FMT_MJPEG, kSize}});
  V4l2Source source = sourceOn(state);
  Frame frame = frameOf(source);
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

// Lent, a frame is the driver's buffer: its picture, and where a GPU finds it as a DMABUF.
void expectLent(const Frame& frame, const V4l2Source& source, int picture) {
  ASSERT_EQ(frame.dmabuf.planes, frame.format == PixelFormat::kNv12 ? 2u : 1u);
  EXPECT_NE(std::ranges::find(source.dmabufs(), frame.dmabuf.fd[0]), source.dmabufs().end());
  EXPECT_NE(frame.image.data, frame.loan.own.data);
  const auto pitch = static_cast<std::uint32_t>(
      frame.format == PixelFormat::kNv12 ? kSize.width : kSize.width * 2);
  EXPECT_EQ(frame.dmabuf.pitch[0], pitch);
  EXPECT_EQ(frame.dmabuf.offset[0], 0u);
  if (frame.dmabuf.planes == 2) {
    EXPECT_EQ(frame.dmabuf.fd[1], frame.dmabuf.fd[0]);  // NV12 in one buffer: chroma after luma
    EXPECT_EQ(frame.dmabuf.offset[1], pitch * static_cast<std::uint32_t>(kSize.height));
  }
  EXPECT_GE(cv::PSNR(bgrOf(frame), surroundd::testing::syntheticPicture(kSize, picture)), 28.0);
}

TEST(V4l2Source, LendsItsBuffersToFramesWhileTwoStayWithTheDriver) {
  for (const auto fourcc : {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_NV12}) {
    SCOPED_TRACE(testing::fourccName(fourcc));
    const auto state = deviceOffering({{fourcc, kSize}});
    state->exportsDmabuf = true;
    V4l2Source source = sourceOn(state);  // 4 buffers
    EXPECT_EQ(source.lendBuffers(), nullptr);
    FramePool pool(4, kSize, source.pixelFormat());
    std::vector<const uchar*> own;
    std::vector<FrameRef> held;
    for (int k = 0; k < 3; ++k) {
      held.push_back(pool.acquire(std::chrono::milliseconds(0)));
      own.push_back(held.back()->image.data);
      const std::uint64_t queued = state->queued;
      ASSERT_EQ(source.read(*held.back()), ReadStatus::kFrame) << source.lastError();
      if (k < 2) {
        expectLent(*held.back(), source, k);
        EXPECT_EQ(state->queued, queued) << "a lent buffer went back to the driver";
      } else {  // two lent, two with the driver: copied
        EXPECT_EQ(held.back()->dmabuf.planes, 0u);
        EXPECT_EQ(held.back()->image.data, own.back());
        EXPECT_EQ(state->queued, queued + 1);
      }
    }
    const std::uint64_t queued = state->queued;
    held.front().reset();  // back to the pool: its buffer back to the driver
    EXPECT_EQ(state->queued, queued + 1);
    FrameRef again = pool.acquire(std::chrono::milliseconds(0));
    EXPECT_EQ(again->image.data, own.front()) << "the frame's own picture is back";
    EXPECT_EQ(again->dmabuf.planes, 0u);
    ASSERT_EQ(source.read(*again), ReadStatus::kFrame) << source.lastError();
    expectLent(*again, source, 3);
    EXPECT_NE(again->dmabuf.session, 0u);
  }
}

TEST(V4l2Source, SaysWhyItsFramesCannotBeLentItsBuffersAndCopiesThem) {
  using State = FakeV4l2Device::State;
  struct Case {
    std::uint32_t fourcc;
    const char* why;
    std::function<void(State&)> device;
  };
  for (const auto& [fourcc, why, device] :
       {Case{V4L2_PIX_FMT_MJPEG, "its frames are converted to BGR", [](State&) {}},
        Case{V4L2_PIX_FMT_NV12M, "its NV12 comes in two buffers",
             [](State& s) { s.multiplanar = true; }},
        Case{V4L2_PIX_FMT_YUYV, "its driver exports no DMABUF",
             [](State& s) { s.exportsDmabuf = false; }},
        Case{V4L2_PIX_FMT_YUYV, "its lines are padded",
             [](State& s) {
               s.multiplanar = true;
               s.linePadding = 64;
             }},
        Case{V4L2_PIX_FMT_YUYV, "its driver exported only some of its buffers",
             [](State& s) { s.failedExports = 1; }},
        Case{V4L2_PIX_FMT_YUYV, "it has fewer than three buffers",
             [](State& s) { s.grantedBuffers = 2; }},
        Case{V4L2_PIX_FMT_YUYV, "its driver cannot free buffers that a frame still holds",
             [](State& s) { s.orphanedBuffers = false; }}}) {
    SCOPED_TRACE(why);
    const auto state = deviceOffering({{fourcc, kSize}});
    state->exportsDmabuf = true;
    device(*state);
    V4l2Source source = sourceOn(state);
    const char* refusal = source.lendBuffers();
    ASSERT_NE(refusal, nullptr);
    EXPECT_THAT(refusal, HasSubstr(why));
    Frame frame = frameOf(source);
    ASSERT_EQ(source.read(frame), ReadStatus::kFrame) << source.lastError();
    EXPECT_EQ(frame.dmabuf.planes, 0u);
    EXPECT_FALSE(frame.loan.lender);
  }
}

// A frame is a plain struct and may be copied, loan and all: its buffer goes back to the driver
// once, however many copies end their loan, and the count of buffers lent stays right.
TEST(V4l2Source, ABufferGivenBackTwiceGoesBackToTheDriverOnce) {
  const auto state = deviceOffering({{V4L2_PIX_FMT_YUYV, kSize}});
  state->exportsDmabuf = true;
  V4l2Source source = sourceOn(state);  // 4 buffers: two may be lent at once
  ASSERT_EQ(source.lendBuffers(), nullptr);
  FramePool pool(4, kSize, source.pixelFormat());
  FrameRef lent = pool.acquire(std::chrono::milliseconds(0));
  ASSERT_EQ(source.read(*lent), ReadStatus::kFrame);
  ASSERT_EQ(lent->dmabuf.planes, 1u);
  Frame copy = *lent;
  const std::uint64_t queued = state->queued;
  endLoan(copy);
  EXPECT_EQ(state->queued, queued + 1);
  lent.reset();
  EXPECT_EQ(state->queued, queued + 1) << "one buffer queued twice";
  std::vector<FrameRef> held;
  for (int k = 0; k < 3; ++k) {
    held.push_back(pool.acquire(std::chrono::milliseconds(0)));
    ASSERT_EQ(source.read(*held.back()), ReadStatus::kFrame) << source.lastError();
    EXPECT_EQ(held.back()->dmabuf.planes, k < 2 ? 1u : 0u) << "frame " << k;
  }
}

// The capture thread lends the buffers; the consumer lets the frames go on its own thread, as the
// pipeline does (run under ThreadSanitizer in CI).
TEST(V4l2Source, FramesLetGoOnAnotherThreadGiveTheirBuffersBack) {
  const auto state = deviceOffering({{V4L2_PIX_FMT_NV12, kSize}});
  state->exportsDmabuf = true;
  CameraStream camera(
      "front",
      std::make_unique<V4l2Source>("front", settingsFor(), std::make_unique<FakeV4l2Device>(state)),
      4);
  ASSERT_EQ(camera.lendBuffers(), nullptr);
  camera.start();
  int lent = 0;
  for (int k = 0; k < 40; ++k) {
    FrameRef frame;
    ASSERT_EQ(camera.next(frame, std::chrono::seconds(5)), CameraStream::Next::kFrame);
    lent += frame->dmabuf.planes > 0 ? 1 : 0;
    const auto us = std::chrono::duration_cast<std::chrono::microseconds>(frame->timestamp);
    const auto picture = static_cast<int>((us.count() - state->firstTimestampUs) / state->periodUs);
    EXPECT_GE(cv::PSNR(bgrOf(*frame), surroundd::testing::syntheticPicture(kSize, picture)), 28.0)
        << "frame " << k;
  }
  camera.stop();
  EXPECT_GT(lent, 0);
  EXPECT_EQ(camera.stats().faults, 0u) << "a buffer the driver refused back";
}

// The kernel keeps a buffer mapped until it is unmapped, whatever happens to its device; so does
// the source, until the frame lent it lets it go.
TEST(V4l2Source, AFrameKeepsItsLentBufferWhenTheCameraIsLostAndReopened) {
  const auto state = deviceOffering({{V4L2_PIX_FMT_YUYV, kSize}});
  state->exportsDmabuf = true;
  auto source =
      std::make_unique<V4l2Source>("front", settingsFor(), std::make_unique<FakeV4l2Device>(state));
  ASSERT_EQ(source->lendBuffers(), nullptr);
  FramePool pool(2, kSize, source->pixelFormat());
  FrameRef lent = pool.acquire(std::chrono::milliseconds(0));
  ASSERT_EQ(source->read(*lent), ReadStatus::kFrame);
  const cv::Mat picture = lent->image.clone();
  const std::uint64_t lentSession = lent->dmabuf.session;
  state->plugged = false;
  FrameRef next = pool.acquire(std::chrono::milliseconds(0));
  EXPECT_EQ(source->read(*next), ReadStatus::kLost);
  state->plugged = true;
  source->reopen();
  ASSERT_EQ(source->read(*next), ReadStatus::kFrame) << source->lastError();
  const std::uint64_t queued = state->queued;
  EXPECT_EQ(cv::norm(lent->image, picture, cv::NORM_INF), 0.0);
  EXPECT_GT(next->dmabuf.session, lentSession) << "a buffer of the new session under an old name";
  lent.reset();  // its session is over: nothing goes back to the driver
  EXPECT_EQ(state->queued, queued);
  next.reset();
  source.reset();  // and a frame may outlive its source
  EXPECT_EQ(pool.available(), 2u);
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
