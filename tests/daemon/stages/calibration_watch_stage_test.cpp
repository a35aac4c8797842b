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

#include <gmock/gmock.h>
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
  PanoramaStage panorama(config, pool);
  CalibrationWatchStage stage(config, panorama);
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

// The generated fisheye drive under a rig that says the back camera's yaw is 2 degrees more than
// it was (the body masked as rendered), through the panorama and watch stages with
// calibration_watch.correct `correct`: each set is compared by the refinement before the next
// comes (as on a machine that keeps up); the sets go on while a table for corrected mounts is
// built.
class TurnedDrive {
 public:
  static constexpr std::size_t kBack = 2;

  explicit TurnedDrive(const std::string& correct, const std::string& thresholdCm = "5") {
    rig_ = loadRig(kDrive / "rig.yaml");
    const YAML::Node written = YAML::LoadFile((kDrive / "ground_truth.yaml").string());
    for (std::size_t c = 0; c < rig_.cameras.size(); ++c) {
      rig_.cameras[c].bodyMask =
          BodyMaskConfig{BodyMaskConfig::Mode::kReplace,
                         kDrive / written["cameras"][c]["body_mask"].as<std::string>(),
                         {}};
    }
    EXPECT_EQ(rig_.cameras[kBack].calibration.name, "back");
    trueBack_ = rig_.cameras[kBack].calibration.pose;
    auto& pose = rig_.cameras[kBack].calibration.pose;
    auto angles = processing::mountAnglesFromRotation(pose.rotation);
    angles.yawDeg += 2;
    pose.rotation = processing::rotationFromMountAngles(angles);
    writeRigFile(dir_ / "rig.yaml", rig_.cameras,
                 "the drive's, its back camera's yaw 2 degrees off",
                 rig_.vehicle ? &*rig_.vehicle : nullptr);
    config_ = loadConfig(dir_.write("config.yaml", R"(rig: {file: rig.yaml}
panorama: {width_px: 512, height_px: 256, cache_dir: lut-cache}
calibration_watch: {interval_s: 0.5, correct: )" + correct +
                                                       R"(, compare_every_s: 0.5,
                    threshold_cm: )" + thresholdCm + R"(}
outputs:
  - {type: snapshot, stream: panorama, path: panorama.png}
)"));
    for (const auto& camera : rig_.cameras) {
      const auto pictures = testing::decodeAll(kDrive / (camera.calibration.name + ".mkv")).images;
      sets_.resize(std::max(sets_.size(), pictures.size()));
      for (std::size_t k = 0; k < pictures.size(); ++k) sets_[k].push_back(pictures[k]);
    }
    panorama_.emplace(config_, pool_);
    stage_.emplace(config_, *panorama_);
  }

  std::size_t sets() const { return sets_.size(); }
  // Set `k` of the drive (repeating it from its start past its end).
  void process(std::size_t k) {
    const auto& pictures = sets_[k % sets_.size()];
    capture::FrameSet set;
    for (std::size_t c = 0; c < pictures.size(); ++c) {
      if (!pools_[c]) pools_[c].emplace(1, pictures[c].size());
      set.frames[c] = pools_[c]->tryAcquire();
      pictures[c].copyTo(set.frames[c]->image);
    }
    set.cameraCount = pictures.size();
    FrameWork work{.set = set,
                   .bgrBuffers = bgrBuffers_,
                   .streamTime = std::chrono::milliseconds(500 * static_cast<int>(k)),
                   .outputs = outputs_};
    const std::size_t before = compared();
    times_.beginSet();
    panorama_->process(work, times_);
    stage_->process(work, times_);
    times_.endSet();
    for (int wait = 0; wait < 1000 && compared() == before; ++wait) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  PipelineReport report() const {
    PipelineReport report;
    for (const auto& camera : rig_.cameras) {
      report.cameras.emplace_back().name = camera.calibration.name;
    }
    stage_->report(report);
    return report;
  }
  const PanoramaStage& panorama() const { return *panorama_; }
  CalibrationWatchStage& watch() { return *stage_; }
  const processing::Pose& trueBack() const { return trueBack_; }

 private:
  std::size_t compared() const {
    const PipelineReport now = report();
    return now.mountWatch ? now.mountWatch->setsCompared : 0;
  }

  inline static const auto kDrive =
      std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_drive_fisheye_hd";
  const testing::TempDir dir_;
  RigFile rig_;
  processing::Pose trueBack_;
  Config config_;
  std::vector<std::vector<cv::Mat>> sets_;
  WorkPool pool_{1};
  std::optional<PanoramaStage> panorama_;
  std::optional<CalibrationWatchStage> stage_;
  std::array<std::optional<capture::FramePool>, kMaxCameras> pools_;
  std::array<cv::Mat, kMaxCameras> bgrBuffers_;
  PipelineOutputs outputs_{2, false};
  StageTimes times_;
};

// correct: suggest: after the drive's twenty sets the watch suggests turning the back camera back
// by 2 degrees, and no other; the seams it touches would come together. Nothing is changed.
TEST(CalibrationWatchStage, SuggestsTheMountThatBringsATurnedCameraBack) {
  TurnedDrive drive("suggest");
  // Every set, then the first again to read the last solution.
  for (std::size_t k = 0; k <= drive.sets(); ++k) drive.process(k);
  const PipelineReport report = drive.report();
  ASSERT_TRUE(report.mountWatch);
  EXPECT_EQ(report.mountWatch->setsCompared, drive.sets() + 1);
  EXPECT_EQ(report.mountWatch->applied, 0U);
  EXPECT_EQ(drive.panorama().generation(), 0U);
  for (std::size_t c = 0; c < report.cameras.size(); ++c) {
    const auto& suggestion = report.cameras[c].mountSuggestion;
    EXPECT_EQ(suggestion.has_value(), c == TurnedDrive::kBack) << report.cameras[c].name;
    if (c != TurnedDrive::kBack || !suggestion) continue;
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

// correct: apply: once two solutions agree, the panorama switches to the corrected mounts at a set
// boundary (its table built beside the sets); the back camera's mount is then within 0.2 degrees
// of the one that rendered the drive, the others as they were, the check finds the seams together
// and the correction is kept.
TEST(CalibrationWatchStage, AppliesTheCorrectionAndKeepsItWhereTheSeamsComeTogether) {
  TurnedDrive drive("apply");
  const processing::Rig before = drive.panorama().rig();
  std::size_t k = 0;
  for (; k < 6 * drive.sets(); ++k) {
    drive.process(k);
    const PipelineReport report = drive.report();
    if (report.mountWatch && report.mountWatch->applied > 0 && !report.mountWatch->checking) break;
  }
  const PipelineReport report = drive.report();
  std::printf("%zu sets\n%s", k + 1, statusText(report).c_str());
  ASSERT_TRUE(report.mountWatch);
  EXPECT_EQ(report.mountWatch->applied, 1U);
  EXPECT_EQ(report.mountWatch->reverted, 0U);
  EXPECT_FALSE(report.mountWatch->checking);
  ASSERT_EQ(drive.panorama().generation(), 1U);
  const processing::Rig& corrected = drive.panorama().rig();
  for (std::size_t c = 0; c < corrected.cameras.size(); ++c) {
    const processing::Pose& expected =
        c == TurnedDrive::kBack ? drive.trueBack() : before.cameras[c].pose;
    const processing::MountAngles off =
        processing::mountAngleChange(expected, corrected.cameras[c].pose);
    EXPECT_LT(std::abs(off.yawDeg) + std::abs(off.pitchDeg) + std::abs(off.rollDeg),
              c == TurnedDrive::kBack ? 0.2 : 1e-9)
        << corrected.cameras[c].name;
  }
  // One measurement each (the check takes their median): 9-11 cm before.
  for (const SeamReport& seam : report.seams) {
    if (seam.name.find("back") == std::string::npos || !seam.shiftCm) continue;
    EXPECT_LT(*seam.shiftCm, 3.0) << seam.name;
  }

  // surroundctl calibration revert: back to the mounts the run started with, and no more made.
  const auto mounts = drive.watch().correctedMounts();
  ASSERT_EQ(mounts.size(), 1U);
  EXPECT_EQ(mounts[0].first, "back");
  EXPECT_THAT(drive.watch().revert(), ::testing::HasSubstr("going back to the mounts the run "
                                                           "started with (or last accepted) for "
                                                           "camera 'back'"));
  // From the set after the last one processed (the loop above stopped at k).
  for (const std::size_t end = ++k + drive.sets(); k < end; ++k) drive.process(k);
  EXPECT_EQ(drive.panorama().generation(), 2U);
  EXPECT_TRUE(drive.watch().correctedMounts().empty());
  EXPECT_EQ(drive.report().mountWatch->applied, 1U);
  EXPECT_THAT(drive.watch().revert(), ::testing::HasSubstr("nothing to take back"));
}

// The same, where the seams must come within half a centimetre (as the drive's cannot: its
// corrected seams measure 0.3-1.4 cm): the check finds the correction did not hold, the panorama
// goes back to the mounts before it, and nothing more is applied.
TEST(CalibrationWatchStage, TakesTheCorrectionBackWhereTheSeamsDoNotComeTogether) {
  TurnedDrive drive("apply", "0.5");
  const processing::Rig before = drive.panorama().rig();
  std::size_t k = 0;
  for (; k < 6 * drive.sets() && drive.panorama().generation() < 2; ++k) drive.process(k);
  for (const std::size_t end = k + drive.sets(); k < end; ++k) drive.process(k);
  const PipelineReport report = drive.report();
  std::printf("%zu sets\n%s", k, statusText(report).c_str());
  ASSERT_TRUE(report.mountWatch);
  EXPECT_EQ(report.mountWatch->applied, 1U);
  EXPECT_EQ(report.mountWatch->reverted, 1U);
  EXPECT_EQ(drive.panorama().generation(), 2U);
  const processing::Rig& now = drive.panorama().rig();
  for (std::size_t c = 0; c < now.cameras.size(); ++c) {
    EXPECT_EQ(now.cameras[c].pose.rotation, before.cameras[c].pose.rotation) << c;
    EXPECT_EQ(now.cameras[c].pose.position, before.cameras[c].pose.position) << c;
  }
  // Still suggested.
  EXPECT_TRUE(report.cameras[TurnedDrive::kBack].mountSuggestion.has_value());
}

// Whether a correction held: a seam it touched, measured since, within the threshold and no more
// than worseCm above where it was; one not measured since says nothing.
TEST(CalibrationWatch, ACorrectionHoldsOnlyWhereEverySeamItTouchedComesOutTogether) {
  const auto held = [](std::vector<SeamCheck> seams) { return correctionHeld(seams, 5.0, 1.0); };
  EXPECT_TRUE(held({{10.3, {0.8, 1.2, 0.9}}, {13.9, {1.1, 0.7, 1.4}}}));
  EXPECT_TRUE(held({{std::nullopt, {2.0, 3.0, 2.5}}, {13.9, {}}}));
  EXPECT_TRUE(held({{1.0, {1.8, 1.9, 2.1}}}));    // within the measurements' scatter
  EXPECT_FALSE(held({{1.0, {2.5, 2.6, 2.4}}}));   // worse than before
  EXPECT_FALSE(held({{10.3, {6.0, 6.5, 5.5}}}));  // better, but still apart
  EXPECT_FALSE(held({{10.3, {0.8, 1.0, 0.9}}, {3.0, {9.0, 8.0, 12.0}}}));  // one seam of two
  // The median: one passing car's measurement does not decide.
  EXPECT_TRUE(held({{10.3, {0.8, 30.0, 0.9}}}));
}

}  // namespace
}  // namespace surroundd::daemon
