// The drift watch as a stage on its own, given a hand-built FrameWork: synth_seams' first frames
// under the calibration that rendered them, then with the front camera's yaw turned 2 degrees.
// Its report names the seams with their shifts and the front camera alone as drifting, its time
// goes to the "watch" column for the sets it measured and to none for those between. With
// correct: suggest, a generated drive's sets: the mount that brings a turned camera back.

#include "daemon/stages/calibration_watch_stage.hpp"

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "capture/frame.hpp"
#include "capture/frame_set.hpp"
#include "common/work_pool.hpp"
#include "daemon/config/config.hpp"
#include "daemon/config/panorama_setup.hpp"
#include "tests/daemon/stages/seams_frame_set.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {
namespace {

using testing::kSeamsCameras;

// synth_seams' rig, `frontYaw` the front camera's.
Config seamsConfig(const testing::TempDir& dir, const std::string& frontYaw) {
  return testing::seamsConfig(dir, frontYaw, R"(rig: {file: rig.yaml}
panorama: {width_px: 1024, height_px: 512, cache_dir: lut-cache}
calibration_watch: {interval_s: 0.2, threshold_cm: 5}
outputs:
  - {type: snapshot, stream: panorama, path: panorama.png}
)");
}

struct Watched {
  PipelineReport report;
  std::uint64_t measuredSets = 0;
};

// The stage given the same set at stream times 0, 0.1 and 0.2 s: measured at 0 and 0.2.
Watched watch(const Config& config) {
  WorkPool pool(1);
  CalibrationWatchStage stage(config, rigOf(config, pool));
  const testing::SeamsFirstFrames frames;
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
  for (const std::string& name : kSeamsCameras) watched.report.cameras.emplace_back().name = name;
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

// correct: suggest, on the generated fisheye drive whose rig says the back camera's yaw is 2
// degrees more than it was (the body masked as rendered): after the drive's twenty sets the watch
// suggests turning the back camera back by 2 degrees, and no other; the seams it touches would
// come together.
TEST(CalibrationWatchStage, SuggestsTheMountThatBringsATurnedCameraBack) {
  const auto drive = std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_drive_fisheye_hd";
  const testing::TempDir dir;
  RigFile rig = loadRig(drive / "rig.yaml");
  const YAML::Node written = YAML::LoadFile((drive / "ground_truth.yaml").string());
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
    rig.cameras[c].bodyMask =
        BodyMaskConfig{BodyMaskConfig::Mode::kReplace,
                       drive / written["cameras"][c]["body_mask"].as<std::string>(),
                       {}};
  }
  const std::size_t back = 2;
  ASSERT_EQ(rig.cameras[back].calibration.name, "back");
  auto& pose = rig.cameras[back].calibration.pose;
  auto angles = processing::mountAnglesFromRotation(pose.rotation);
  angles.yawDeg += 2;
  pose.rotation = processing::rotationFromMountAngles(angles);
  writeRigFile(dir / "rig.yaml", rig.cameras, "the drive's, its back camera's yaw 2 degrees off",
               rig.vehicle ? &*rig.vehicle : nullptr);
  const Config config = loadConfig(dir.write("config.yaml", R"(rig: {file: rig.yaml}
panorama: {width_px: 512, height_px: 256, cache_dir: lut-cache}
calibration_watch: {interval_s: 0.5, correct: suggest, compare_every_s: 0.5}
outputs:
  - {type: snapshot, stream: panorama, path: panorama.png}
)"));

  std::vector<std::vector<cv::Mat>> sets;
  for (const auto& camera : rig.cameras) {
    const auto pictures = testing::decodeAll(drive / (camera.calibration.name + ".mkv")).images;
    sets.resize(std::max(sets.size(), pictures.size()));
    for (std::size_t k = 0; k < pictures.size(); ++k) sets[k].push_back(pictures[k]);
  }
  WorkPool pool(1);
  CalibrationWatchStage stage(config, rigOf(config, pool));
  std::array<std::optional<capture::FramePool>, kMaxCameras> pools;
  std::array<cv::Mat, kMaxCameras> bgrBuffers;
  PipelineOutputs outputs(2, false);
  StageTimes times;
  const auto compared = [&] {
    PipelineReport report;
    stage.report(report);
    return report.mountWatch ? report.mountWatch->setsCompared : 0;
  };
  // Every set, then the first again to read the last solution; each compared before the next.
  for (std::size_t k = 0; k <= sets.size(); ++k) {
    const auto& pictures = sets[k % sets.size()];
    capture::FrameSet set;
    for (std::size_t c = 0; c < pictures.size(); ++c) {
      if (!pools[c]) pools[c].emplace(1, pictures[c].size());
      set.frames[c] = pools[c]->tryAcquire();
      pictures[c].copyTo(set.frames[c]->image);
    }
    set.cameraCount = pictures.size();
    FrameWork work{.set = set,
                   .bgrBuffers = bgrBuffers,
                   .streamTime = std::chrono::milliseconds(500 * static_cast<int>(k)),
                   .outputs = outputs};
    const std::size_t before = compared();
    times.beginSet();
    stage.process(work, times);
    times.endSet();
    for (int wait = 0; wait < 1000 && k < sets.size() && compared() == before; ++wait) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  PipelineReport report;
  for (const auto& camera : rig.cameras) {
    report.cameras.emplace_back().name = camera.calibration.name;
  }
  stage.report(report);
  ASSERT_TRUE(report.mountWatch);
  EXPECT_EQ(report.mountWatch->setsCompared, sets.size());
  for (std::size_t c = 0; c < report.cameras.size(); ++c) {
    const auto& suggestion = report.cameras[c].mountSuggestion;
    EXPECT_EQ(suggestion.has_value(), c == back) << report.cameras[c].name;
    if (c != back || !suggestion) continue;
    EXPECT_NEAR(suggestion->changeDeg.yawDeg, -2, 0.2);
    EXPECT_NEAR(suggestion->changeDeg.pitchDeg, 0, 0.2);
    EXPECT_NEAR(suggestion->changeDeg.rollDeg, 0, 0.2);
  }
  for (const SeamReport& seam : report.seams) {
    if (seam.name.find("back") == std::string::npos) continue;
    ASSERT_TRUE(seam.suggestedCm.has_value()) << seam.name;
    EXPECT_LT(*seam.suggestedCm, 2.0) << seam.name;
  }
  std::printf("%s", statusText(report).c_str());
}

}  // namespace
}  // namespace surroundd::daemon
