// Camera faults in a generated recording (from 0.5 s: 'left' frozen, 'right' black, 'back'
// stopped): the pipeline detects each within 200 ms, keeps going with the others, marks the
// faulty cameras' parts of the panorama and the mosaic, and leaves them out of colour correction.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "daemon/config/panorama_setup.hpp"
#include "daemon/pipeline.hpp"
#include "processing/stitch/panorama_ownership.hpp"
#include "tests/daemon/replay_config.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd::daemon {
namespace {

const std::filesystem::path kRecording =
    std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_faults";

TEST(CameraHealth, FaultsAreDetectedWithin200MsAndMarkedWhileTheOthersGoOn) {
  const testing::TempDir dir;
  Config config = rigReplay(kRecording / "rig.yaml",
                            {snapshotAt(dir / "panorama.png", OutputStream::kPanorama, 0.9),
                             snapshotAt(dir / "mosaic.png", OutputStream::kMosaic, 0.9)});
  config.pipeline.threads = 2;
  useSmallPanorama(config, dir / "lut-cache");

  Pipeline pipeline(config);
  const std::atomic<bool> stop{false};
  const RunSummary summary = pipeline.run(stop);
  EXPECT_EQ(summary.frameSets, 30u);  // 'back' ends, the others go on to the end

  const auto detected = [&](std::size_t camera, capture::CameraHealth health) {
    for (const auto& change : summary.report.healthChanges) {
      if (change.camera == camera && change.to == health) {
        return std::chrono::duration<double>(change.at).count();
      }
    }
    return -1.0;
  };
  // Front: camera 0, right 1, back 2, left 3; the faults start at 0.5 s (frame 15).
  for (const auto& [camera, health] : {std::pair{std::size_t{3}, capture::CameraHealth::kFrozen},
                                       std::pair{std::size_t{1}, capture::CameraHealth::kBlack},
                                       std::pair{std::size_t{2}, capture::CameraHealth::kLost}}) {
    const double at = detected(camera, health);
    SCOPED_TRACE(capture::toString(health));
    EXPECT_GE(at, 0.49);
    EXPECT_LE(at - 0.5, 0.2);
    RecordProperty(std::string("detected_") + capture::toString(health) + "_after_ms",
                   std::to_string(std::lround((at - 0.5) * 1000)));
  }
  for (const auto& change : summary.report.healthChanges)
    EXPECT_NE(change.camera, 0u);  // front is fine

  // The lost camera's part of the panorama is greyed and striped; the front's is its picture.
  const cv::Mat shot = cv::imread((dir / "panorama.png").string());
  ASSERT_EQ(shot.size(), cv::Size(512, 256));
  const processing::PanoramaLut lut = [&] {
    WorkPool pool(1);
    return obtainPanoramaLut(config, rigOf(config, pool), pool);
  }();
  const auto markedShare = [&](std::uint8_t camera) {
    int owned = 0, marked = 0;
    for (int v = 0; v < shot.rows; ++v) {
      for (int u = 0; u < shot.cols; ++u) {
        if (lut.taps[static_cast<std::size_t>(v) * shot.cols + u].camera != camera) continue;
        ++owned;
        const int floor = ((u + v) / 8) % 2 == 0 ? 40 : 100;
        const cv::Vec3b p = shot.at<cv::Vec3b>(v, u);
        marked += p[0] >= floor && p[0] <= floor + 63 && p[1] >= floor && p[1] <= floor + 63 &&
                          p[2] >= floor && p[2] <= floor + 63
                      ? 1
                      : 0;
      }
    }
    return static_cast<double>(marked) / std::max(owned, 1);
  };
  EXPECT_GT(markedShare(2), 0.99);
  EXPECT_GT(markedShare(1), 0.99);
  EXPECT_LT(markedShare(0), 0.5);
  EXPECT_TRUE(std::filesystem::exists(dir / "mosaic.png"));
}

}  // namespace
}  // namespace surroundd::daemon
