// Recordings preloaded into memory in the daemon: `preload` and `format` are read, written back and
// refused where they do not belong, naming the key; the pipeline replays preloaded cameras losing
// nothing; capture.preload_max_mb bounds every preloaded camera together, and the camera that
// would pass it is named with the bytes it needs and those left.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "daemon/pipeline.hpp"
#include "daemon/pipeline_ends.hpp"
#include "tests/daemon/config/config_test_support.hpp"
#include "tests/daemon/replay_config.hpp"

namespace surroundd::daemon {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

TEST_F(ConfigTest, APreloadedFileIsHeldInTheFormatItNames) {
  const Config config =
      loadConfig(configWith("source: {file: left.mkv}", "source: {file: left.mkv, preload: true}"));
  EXPECT_EQ(config.cameras[0].preloaded(), std::nullopt);                 // decoded as it plays
  EXPECT_EQ(config.cameras[1].preloaded(), capture::PixelLayout::kYuyv);  // the default format
  EXPECT_EQ(config.capture.preloadMaxMb, 2048);

  const Config nv12 = loadConfig(configWith(
      "source: {file: left.mkv}", "source: {file: left.mkv, preload: true, format: nv12}"));
  EXPECT_EQ(nv12.cameras[1].preloaded(), capture::PixelLayout::kNv12);
  // And back through a rig file.
  writeRigFile(dir_ / "rig.yaml", nv12.cameras, "test");
  const auto cameras = loadRigFile(dir_ / "rig.yaml");
  EXPECT_EQ(cameras[0].preloaded(), std::nullopt);
  EXPECT_EQ(cameras[1].preloaded(), capture::PixelLayout::kNv12);

  const Config bounded = loadConfig(
      configWith("  sync_tolerance_ms: 5", "  sync_tolerance_ms: 5\n  preload_max_mb: 512"));
  EXPECT_EQ(bounded.capture.preloadMaxMb, 512);
}

TEST_F(ConfigTest, PreloadMistakesAreNamedByTheirKey) {
  expectOneError("source: {file: left.mkv}",
                 "source: {file: left.mkv, preload: true, format: mjpeg}",
                 {where(10, 55),
                  "rig.cameras[1].source.format: expected one of 'yuyv' 'uyvy' 'nv12'", "'mjpeg'"});
  expectOneError("source: {file: left.mkv}", "source: {file: left.mkv, format: nv12}",
                 {"rig.cameras[1].source.format: expected only with 'preload: true'"});
  expectOneError("source: {file: left.mkv}", "source: {file: left.mkv, preload: yes please}",
                 {"rig.cameras[1].source.preload: expected true or false"});
  expectOneError("  sync_tolerance_ms: 5", "  sync_tolerance_ms: 5\n  preload_max_mb: 0",
                 {"capture.preload_max_mb: expected a whole number in [1, 1048576]"});
  for (const auto& [source, kind] :
       {std::pair{"source: {device: /dev/video3, preload: true}", "a V4L2 camera's"},
        std::pair{"source: {libcamera: imx219, preload: true}", "a libcamera camera's"}}) {
    // (A build without libcamera also says so, in a message of its own.)
    EXPECT_THAT(errorsOf(liveConfigWith(source)),
                ::testing::Contains(AllOf(
                    HasSubstr("rig.cameras[1].source.preload: expected only in a file source"),
                    HasSubstr(kind))));
  }
}

// Two cameras preloaded as YUYV and two as NV12: every frame set of the recording comes through,
// none lost, each camera's frames converted from memory.
TEST(PreloadReplay, ThePipelineReplaysPreloadedCamerasLosingNothing) {
  Config config = fixtureReplay("synth_small", {});
  for (std::size_t c = 0; c < config.cameras.size(); ++c) {
    config.cameras[c].preload(c % 2 == 0 ? capture::PixelLayout::kYuyv
                                         : capture::PixelLayout::kNv12);
  }
  Pipeline pipeline(config);
  const std::atomic<bool> stop{false};
  const RunSummary summary = pipeline.run(stop);
  EXPECT_EQ(summary.frameSets, 30u);  // the fixture's 1 s at 30 FPS
  for (const auto& camera : summary.cameras) {
    EXPECT_EQ(camera.frames, 30u);
    EXPECT_EQ(camera.faults, 0u);
  }
}

// The fixture's 320x180 frames take 115200 bytes each as YUYV, 3456000 bytes (3.3 MiB) for 30:
// 5 MiB hold one camera, and the second is refused with what is left.
TEST(PreloadReplay, TheBoundIsForEveryPreloadedCameraTogether) {
  Config config = fixtureReplay("synth_small", {});
  for (auto& camera : config.cameras) camera.preload(capture::PixelLayout::kYuyv);
  config.capture.preloadMaxMb = 5;
  const auto& second = config.cameras[1];
  EXPECT_THAT(
      [&] { openCameras(config); },
      ::testing::ThrowsMessage<capture::CaptureError>(AllOf(
          HasSubstr(fmt::format("camera '{}'", second.calibration.name)),
          HasSubstr(second.replayedFile()->path.string()), HasSubstr("needs 3456000 bytes"),
          HasSubstr("more than the 1786880 bytes (1.7 MiB) allowed by capture.preload_max_mb: 5 "
                    "for every preloaded camera together, less what the cameras before it hold: "
                    "'front' 3.3 MiB"))));
  config.capture.preloadMaxMb = 14;  // 4 x 3.3 MiB
  EXPECT_EQ(openCameras(config).size(), 4u);
}

}  // namespace
}  // namespace surroundd::daemon
