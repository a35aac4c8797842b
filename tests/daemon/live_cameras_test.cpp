// surroundd on four live V4L2 cameras through the kernel: the pipeline on vivid's four capture
// devices (the kernel's virtual video test driver, streaming its colour bars at 10 FPS, two
// through each V4L2 API), which ctest gives it on a virtual machine (LiveCameras.OnVividCameras,
// scripts/device-vm.sh). The cameras are paced by the driver, not replayed: every camera keeps
// streaming, frame sets are matched, and each camera's tile of a lossless video of the mosaic
// shows its bars; and the GPU stitch takes their frames lent the drivers' buffers. Skipped, with a
// message, where the machine has no four vivid devices.

#include "daemon/live_cameras.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "daemon/pipeline.hpp"
#include "render/mosaic.hpp"
#include "tests/daemon/replay_config.hpp"
#include "tests/support/log_capture.hpp"
#include "tests/support/test_support.hpp"
#include "tests/support/vivid_cameras.hpp"

namespace surroundd::daemon {
namespace {

// Stops the run once it has made `sets` frame sets; with `healthy`, sets made while every camera
// was well (a start on the emulated CPU may take seconds, and the cameras are late or lost for a
// while after), or at most ten times as many sets.
class StopAfter final : public PipelineObserver {
 public:
  StopAfter(std::atomic<bool>& stop, std::uint64_t sets, bool healthy = false)
      : stop_(stop), sets_(sets), healthy_(healthy) {}
  void onLoop(Pipeline& pipeline, std::chrono::steady_clock::time_point /*now*/,
              std::uint64_t frameSets) override {
    if (healthy_ && frameSets > counted_) {
      const PipelineReport report = pipeline.report();
      const bool well = std::ranges::all_of(report.cameras, [](const CameraReport& camera) {
        return camera.health == capture::CameraHealth::kOk;
      });
      if (well) healthySets_ += frameSets - counted_;
      counted_ = frameSets;
    }
    if ((healthy_ ? healthySets_ : frameSets) >= sets_ || frameSets >= 10 * sets_) stop_ = true;
  }
  void onStopping() override {}

 private:
  std::atomic<bool>& stop_;
  std::uint64_t sets_;
  bool healthy_;
  std::uint64_t counted_ = 0;
  std::uint64_t healthySets_ = 0;
};

// The synthetic rig's calibration, at vivid's webcam size (320x180), its frames from vivid's
// devices, camera i's in formats[i % 2].
Config vividConfig(const std::vector<std::filesystem::path>& devices, const testing::TempDir& dir,
                   const OutputConfig& output, std::array<capture::V4l2Format, 2> formats) {
  Config config = fixtureReplay("synth_small", {output});
  config.capture.pacing = capture::Pacing::kRealtime;
  config.panorama.cacheDir = dir.path() / "cache";
  // vivid's devices run on timers of their own, at phases that drift apart: within 10 ms (the
  // default) four of them rarely meet, and a run waited minutes for its sets; within half a
  // period each camera's frame has its partners.
  config.capture.syncToleranceMs = 50;
  for (std::size_t i = 0; i < config.cameras.size(); ++i) {
    RigCamera& camera = config.cameras[i];
    capture::V4l2Settings settings = testing::vividSettings(devices[i], formats[i % 2], {320, 180});
    // 10 FPS: time for a set on the machine's emulated CPU, sanitizers and all.
    settings.fps = 10;
    camera.source = settings;
    // vivid's bars stand still (only its text at the top changes): left on, the check reports
    // every camera frozen after a second, rightly, and the mosaic dims their tiles.
    camera.frozenCheck = FrozenCheck::kOff;
  }
  return config;
}

std::vector<std::string> namesOf(const Config& config) {
  std::vector<std::string> names;
  for (const auto& camera : config.cameras) names.push_back(camera.calibration.name);
  return names;
}

class LiveCameras : public ::testing::Test {
 protected:
  void SetUp() override {
    devices_ = testing::vividCameras();
    if (devices_.size() < 4) {
      GTEST_SKIP() << "no four vivid devices here (ctest runs this on a virtual machine's: "
                      "LiveCameras.OnVividCameras)";
    }
  }
  std::vector<std::filesystem::path> devices_;
  const testing::TempDir dir_;
};

// Issue 50: bring-up. --list-cameras shows each capture device with its formats, sizes and rates;
// `device: auto` takes the capture devices no camera names, in number order; --check-config asks
// each device for the camera's format and size and names what it offers when it has not.
TEST_F(LiveCameras, TheyAreListedTakenByDeviceAutoAndCheckedForTheFormatAndSize) {
  std::ostringstream listed;
  listCameras(listed);
  for (const auto& device : devices_) {
    EXPECT_THAT(listed.str(), ::testing::HasSubstr(device.string() + ": 'vivid")) << listed.str();
  }
  EXPECT_THAT(listed.str(),
              ::testing::AllOf(::testing::HasSubstr("YUYV"), ::testing::HasSubstr("320x180 ("),
                               ::testing::HasSubstr(" fps)")))
      << listed.str();

  OutputConfig video = videoOutputAt(dir_.path() / "unused.mkv");
  Config config =
      vividConfig(devices_, dir_, video, {capture::V4l2Format::kYuyv, capture::V4l2Format::kNv12});
  // The second camera named, the others auto: they take the rest, in number order.
  auto sorted = devices_;
  std::ranges::sort(sorted, {}, [](const std::filesystem::path& p) {
    return std::stoi(p.filename().string().substr(5));
  });
  for (std::size_t i = 0; i < 4; ++i) {
    config.cameras[i].v4l2()->device = i == 1 ? sorted[0] : std::filesystem::path("auto");
  }
  std::vector<std::string> said;
  const auto cameras = withAutoDevices(config.cameras, said);
  ASSERT_EQ(said.size(), 3U);
  EXPECT_EQ(cameras[0].v4l2()->device, sorted[1]);
  EXPECT_EQ(cameras[1].v4l2()->device, sorted[0]);
  EXPECT_EQ(cameras[2].v4l2()->device, sorted[2]);
  EXPECT_EQ(cameras[3].v4l2()->device, sorted[3]);
  EXPECT_THAT(said[0], ::testing::HasSubstr(
                           fmt::format("camera 'front': device auto is {}", sorted[1].string())));
  EXPECT_THAT(cameraDeviceProblems(cameras), ::testing::IsEmpty());

  // A fifth camera finds none left.
  auto five = config.cameras;
  five.push_back(five.back());
  five.back().calibration.name = "fifth";
  five.back().v4l2()->device = "auto";
  try {
    withAutoDevices(five, said);
    ADD_FAILURE() << "a fifth camera was given a device";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(
        error.what(),
        ::testing::AllOf(::testing::HasSubstr("camera 'fifth': device auto: no V4L2 capture"),
                         ::testing::HasSubstr("found 4")));
  }

  // A size the devices do not offer: each camera named, with what its device offers.
  auto odd = cameras;
  for (auto& camera : odd) camera.v4l2()->size = {333, 111};
  const auto problems = cameraDeviceProblems(odd);
  ASSERT_EQ(problems.size(), 4U);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_THAT(
        problems[i],
        ::testing::AllOf(
            ::testing::HasSubstr(fmt::format("camera '{}': {}", config.cameras[i].calibration.name,
                                             odd[i].v4l2()->device.string())),
            ::testing::HasSubstr("333x111 (it offers"), ::testing::HasSubstr("320x180")));
  }
}

TEST_F(LiveCameras, FourV4l2CamerasThroughTheKernelMakeTheMosaicAndMatchedSets) {
  OutputConfig video = videoOutputAt(dir_.path() / "mosaic.mkv", losslessBgr());
  video.stream = OutputStream::kMosaic;
  const Config config =
      vividConfig(devices_, dir_, video, {capture::V4l2Format::kYuyv, capture::V4l2Format::kNv12});
  const std::vector<std::string> names = namesOf(config);
  std::atomic<bool> stop{false};
  StopAfter observer(stop, 15);
  Pipeline pipeline(config);
  const RunSummary summary = pipeline.run(stop, &observer);

  ASSERT_GE(summary.frameSets, 15U);
  EXPECT_EQ(summary.failedOutputs, 0U);
  EXPECT_EQ(summary.failedSets, 0U);
  ASSERT_EQ(summary.cameras.size(), 4U);
  // Every camera streamed through the kernel, and none failed a read.
  for (std::size_t camera = 0; camera < 4; ++camera) {
    EXPECT_GE(summary.cameras[camera].frames, summary.frameSets) << names[camera];
    EXPECT_EQ(summary.cameras[camera].faults, 0U) << names[camera];
  }
  // vivid's devices run on timers of their own, not one clock, and the machine's CPU is
  // emulated: a camera may fall out of sync with the others, or behind (lost), for a while, and
  // is reported so, its tile dimmed or grey meanwhile. Nothing else is wrong with them.
  for (const auto& change : summary.report.healthChanges) {
    EXPECT_THAT(change.to,
                ::testing::AnyOf(capture::CameraHealth::kOk, capture::CameraHealth::kOutOfSync,
                                 capture::CameraHealth::kLost))
        << names[change.camera] << ": " << toString(change.from) << " -> " << toString(change.to);
  }
  const auto frames = testing::decodeAll(video.path).images;
  // Live, an output that falls behind drops its oldest picture instead of holding the cameras.
  ASSERT_LE(frames.size(), summary.frameSets);
  ASSERT_GE(frames.size(), summary.frameSets / 2);
  // Each camera's tile shows vivid's colour bars, undimmed, in some picture: in each coloured
  // bar the channels it has are near 191 and those it has not near 0.
  const render::Mosaic mosaic(frames.front().size(), names);
  for (std::size_t camera = 0; camera < 4; ++camera) {
    const cv::Rect tile = mosaic.tile(camera);
    const auto showsTheBars = [&](const cv::Mat& picture) {
      for (std::size_t bar = 0; bar < testing::kVividBars.size(); ++bar) {
        const int x = tile.x + static_cast<int>((2 * bar + 1)) * tile.width / 16;
        const cv::Vec3b& shown = picture.at<cv::Vec3b>(tile.y + tile.height * 5 / 6, x);
        for (std::size_t c = 0; c < 3; ++c) {
          if (std::abs(shown[static_cast<int>(c)] - testing::kVividBars[bar][c]) > 16) return false;
        }
      }
      return true;
    };
    EXPECT_TRUE(std::ranges::any_of(frames, showsTheBars)) << names[camera];
  }
}

// The GPU stitch on live cameras: their frames lent the drivers' buffers, which the stitch
// imports where the driver can and uploads where not (this machine's llvmpipe refuses vivid's
// DMABUFs), saying which; the buffers go back to the drivers as the sets end, so that every
// camera streams on.
TEST_F(LiveCameras, TheGpuStitchTakesFramesLentTheDriversBuffers) {
  OutputConfig video = videoOutputAt(dir_.path() / "surround.mkv");
  video.stream = OutputStream::kSurround;
  Config config =
      vividConfig(devices_, dir_, video, {capture::V4l2Format::kYuyv, capture::V4l2Format::kYuyv});
  config.processing.backend = ProcessingBackend::kGpu;
  config.render.widthPx = 320;
  config.render.heightPx = 180;
  config.panorama.widthPx = 512;  // the LUT built in a second on the emulated CPU
  config.panorama.heightPx = 256;
  const std::vector<std::string> names = namesOf(config);
  const testing::LogCapture log;
  std::atomic<bool> stop{false};
  StopAfter observer(stop, 10, true);
  RunSummary summary;
  {
    Pipeline pipeline(config);
    summary = pipeline.run(stop, &observer);
  }
  ASSERT_GE(summary.frameSets, 10U);
  EXPECT_EQ(summary.failedSets, 0U);
  for (std::size_t camera = 0; camera < 4; ++camera) {
    EXPECT_GE(summary.cameras[camera].frames, summary.frameSets) << names[camera];
    EXPECT_EQ(summary.cameras[camera].faults, 0U) << names[camera];
  }
  const auto lines = log.lines();
  const auto said = [&](const std::string& text) {
    return std::ranges::count_if(
        lines, [&](const std::string& line) { return line.find(text) != std::string::npos; });
  };
  for (const auto& name : names) {
    EXPECT_EQ(said(fmt::format("camera '{}': frames lent the driver's buffers", name)), 1) << name;
  }
  // Each camera whose lent frame reached a GPU stitch (a set with a camera late or lost is
  // stitched on the CPU, and an emulated CPU makes them late) says once which way its frames go.
  std::size_t saidWhichWay = 0;
  for (const auto& name : names) {
    const auto ways =
        said(fmt::format("camera '{}': frames taken from their DMABUFs", name)) +
        said(fmt::format("camera '{}': frames uploaded through pixel buffers: the driver "
                         "refused to import a DMABUF",
                         name));
    EXPECT_LE(ways, 1) << name;
    saidWhichWay += static_cast<std::size_t>(ways);
  }
  EXPECT_GE(saidWhichWay, 1U) << fmt::format("{}", fmt::join(lines, "\n"));
}

// Anywhere: a device that is not there is named with the camera; `device: auto` on a machine with
// no capture device says so; the list says there is none.
TEST(CameraDevices, AMissingDeviceIsNamedAndAutoWithNoneThereSaysSo) {
  const testing::TempDir dev;
  Config config = fixtureReplay("synth_small", {});
  for (auto& camera : config.cameras) {
    camera.source = testing::vividSettings(dev.path() / "video9", capture::V4l2Format::kAuto);
  }
  const auto problems = cameraDeviceProblems(config.cameras);
  ASSERT_EQ(problems.size(), config.cameras.size());
  EXPECT_EQ(problems[0], fmt::format("camera 'front': {}: cannot open: No such file or directory",
                                     (dev.path() / "video9").string()));

  config.cameras[2].v4l2()->device = "auto";
  std::vector<std::string> said;
  try {
    withAutoDevices(config.cameras, said, dev.path());
    ADD_FAILURE() << "a camera was given a device where there is none";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), ::testing::HasSubstr("camera 'back': device auto: no V4L2 capture "
                                                   "device is left for it (found 0)"));
  }
  std::ostringstream listed;
  listCameras(listed, dev.path());
  EXPECT_THAT(listed.str(),
              ::testing::HasSubstr(fmt::format("no V4L2 capture device in {} (0 video nodes)",
                                               dev.path().string())));
}

}  // namespace
}  // namespace surroundd::daemon
