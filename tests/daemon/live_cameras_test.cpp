// surroundd on four live V4L2 cameras through the kernel: the pipeline on vivid's four capture
// devices (the kernel's virtual video test driver, streaming its colour bars at 10 FPS, two
// through each V4L2 API), which ctest gives it on a virtual machine (LiveCameras.OnVividCameras,
// scripts/device-vm.sh). The cameras are paced by the driver, not replayed: every camera keeps
// streaming, frame sets are matched, and each camera's tile of a lossless video of the mosaic
// shows its bars. Skipped, with a message, where the machine has no four vivid devices.

#include <algorithm>
#include <array>
#include <atomic>
#include <filesystem>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "daemon/pipeline.hpp"
#include "render/mosaic.hpp"
#include "tests/daemon/replay_config.hpp"
#include "tests/support/test_support.hpp"
#include "tests/support/vivid_cameras.hpp"

namespace surroundd::daemon {
namespace {

// Stops the run once it has made `sets` frame sets.
class StopAfter final : public PipelineObserver {
 public:
  StopAfter(std::atomic<bool>& stop, std::uint64_t sets) : stop_(stop), sets_(sets) {}
  void onLoop(Pipeline& /*pipeline*/, std::chrono::steady_clock::time_point /*now*/,
              std::uint64_t frameSets) override {
    if (frameSets >= sets_) stop_ = true;
  }
  void onStopping() override {}

 private:
  std::atomic<bool>& stop_;
  std::uint64_t sets_;
};

TEST(LiveCameras, FourV4l2CamerasThroughTheKernelMakeTheMosaicAndMatchedSets) {
  const auto devices = testing::vividCameras();
  if (devices.size() < 4) {
    GTEST_SKIP() << "no four vivid devices here (ctest runs this on a virtual machine's: "
                    "LiveCameras.OnVividCameras)";
  }
  const testing::TempDir dir;
  OutputConfig video = videoOutputAt(dir.path() / "mosaic.mkv");
  video.stream = OutputStream::kMosaic;
  video.crf = 0;
  video.pixelFormat = "bgr24";
  // The synthetic rig's calibration, at vivid's webcam size (320x180), its frames from vivid.
  Config config = fixtureReplay("synth_small", {video});
  config.capture.pacing = capture::Pacing::kRealtime;
  config.panorama.cacheDir = dir.path() / "cache";
  std::vector<std::string> names;
  for (std::size_t i = 0; i < config.cameras.size(); ++i) {
    RigCamera& camera = config.cameras[i];
    camera.source.reset();
    capture::V4l2Settings settings;
    settings.device = devices[i];
    settings.size = {320, 180};
    settings.format = i % 2 == 0 ? capture::V4l2Format::kYuyv : capture::V4l2Format::kNv12;
    settings.timeout = std::chrono::milliseconds(3000);  // an emulated CPU draws the bars slowly
    // 10 FPS: time for a set on the machine's emulated CPU, sanitizers and all.
    settings.fps = 10;
    camera.device = settings;
    // vivid's bars stand still (only its text at the top changes): left on, the check reports
    // every camera frozen after a second, rightly, and the mosaic dims their tiles.
    camera.frozenCheck = FrozenCheck::kOff;
    names.push_back(camera.calibration.name);
  }
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
  for (const auto& change : summary.healthChanges) {
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

}  // namespace
}  // namespace surroundd::daemon
