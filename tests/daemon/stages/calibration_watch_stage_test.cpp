// The drift watch as a stage on its own, given a hand-built FrameWork: synth_seams' first frames
// under the calibration that rendered them, then with the front camera's yaw turned 2 degrees.
// Its report names the seams with their shifts and the front camera alone as drifting, its time
// goes to the "watch" column for the sets it measured and to none for those between.

#include "daemon/stages/calibration_watch_stage.hpp"

#include <array>
#include <filesystem>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "capture/frame.hpp"
#include "capture/frame_set.hpp"
#include "common/work_pool.hpp"
#include "daemon/config.hpp"
#include "daemon/panorama_setup.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {
namespace {

const std::filesystem::path kSeams = std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_seams";
const std::array<std::string, 4> kCameras{"front", "right", "back", "left"};

// synth_seams' rig with its recordings where the config finds them; `yaw` the front camera's.
Config seamsConfig(const testing::TempDir& dir, const std::string& frontYaw) {
  std::string rig = testing::fileBytes(kSeams / "rig.yaml");
  for (const std::string& name : kCameras) {
    const std::string source = "file: " + name + ".mkv";
    rig.replace(rig.find(source), source.size(), "file: " + (kSeams / (name + ".mkv")).string());
  }
  const std::string yaw = "yaw_deg: 0,";  // the front camera's, the first
  rig.replace(rig.find(yaw), yaw.size(), "yaw_deg: " + frontYaw + ",");
  dir.write("rig.yaml", rig);
  return loadConfig(dir.write("config.yaml", R"(rig: {file: rig.yaml}
panorama: {width_px: 1024, height_px: 512, cache_dir: lut-cache}
calibration_watch: {interval_s: 0.2, threshold_cm: 5}
outputs:
  - {type: snapshot, stream: panorama, path: panorama.png}
)"));
}

// Each camera's first frame, in pooled frames as a camera stream hands them over.
class FirstFrames {
 public:
  FirstFrames() {
    for (std::size_t c = 0; c < kCameras.size(); ++c) {
      const cv::Mat picture =
          testing::decodeAll(kSeams / (kCameras[c] + ".mkv"), false, 1).images.at(0);
      pools_[c].emplace(1, picture.size());
      set.frames[c] = pools_[c]->tryAcquire();
      picture.copyTo(set.frames[c]->image);
    }
    set.cameraCount = kCameras.size();
  }
  capture::FrameSet set;

 private:
  std::array<std::optional<capture::FramePool>, kMaxCameras> pools_;
};

struct Watched {
  PipelineReport report;
  std::uint64_t measuredSets = 0;
};

// The stage given the same set at stream times 0, 0.1 and 0.2 s: measured at 0 and 0.2.
Watched watch(const Config& config) {
  WorkPool pool(1);
  CalibrationWatchStage stage(config, rigOf(config, pool));
  const FirstFrames frames;
  std::array<cv::Mat, kMaxCameras> bgrBuffers;
  PipelineOutputs outputs(30, false);
  StageTimes times;
  for (const int ms : {0, 100, 200}) {
    FrameWork work{.set = frames.set,
                   .bgrBuffers = bgrBuffers,
                   .streamTime = std::chrono::milliseconds(ms),
                   .outputs = outputs};
    times.beginSet();
    stage.process(work, times);
    times.endSet();
  }
  Watched watched;
  for (const std::string& name : kCameras) watched.report.cameras.emplace_back().name = name;
  stage.report(watched.report);
  watched.measuredSets = times.histograms()[static_cast<std::size_t>(Stage::kWatch)].count();
  return watched;
}

TEST(CalibrationWatchStage, ReportsEachSeamAndNamesTheTurnedCamera) {
  const testing::TempDir dir;
  const Watched exact = watch(seamsConfig(dir, "0"));
  EXPECT_EQ(exact.measuredSets, 2U);
  ASSERT_EQ(exact.report.seams.size(), 4U);
  for (const SeamReport& seam : exact.report.seams) {
    ASSERT_TRUE(seam.shiftCm.has_value()) << seam.name;
    EXPECT_LT(*seam.shiftCm, 2.0) << seam.name;
    EXPECT_FALSE(seam.misaligned) << seam.name;
  }
  for (const CameraReport& camera : exact.report.cameras) {
    EXPECT_FALSE(camera.calibrationDrifting) << camera.name;
  }

  const Watched turned = watch(seamsConfig(dir, "2"));
  ASSERT_EQ(turned.report.seams.size(), 4U);
  for (const SeamReport& seam : turned.report.seams) {
    ASSERT_TRUE(seam.shiftCm.has_value()) << seam.name;
    // 4.1 m from the camera, 2 degrees: 14 cm.
    const bool front = seam.name.find("front") != std::string::npos;
    if (front) {
      EXPECT_NEAR(*seam.shiftCm, 13.5, 1.0) << seam.name;
    }
    EXPECT_EQ(seam.misaligned, front) << seam.name;
  }
  for (const CameraReport& camera : turned.report.cameras) {
    EXPECT_EQ(camera.calibrationDrifting, camera.name == "front") << camera.name;
  }
}

}  // namespace
}  // namespace surroundd::daemon
