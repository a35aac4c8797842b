#include "daemon/stages/calibration_watch_stage.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "daemon/panorama_setup.hpp"

namespace surroundd::daemon {

CalibrationWatchStage::CalibrationWatchStage(const Config& config, const processing::Rig& rig)
    : interval_(std::chrono::duration_cast<std::chrono::nanoseconds>(
          std::chrono::duration<double>(config.calibrationWatch.intervalS))),
      thresholdCm_(config.calibrationWatch.thresholdCm),
      drifting_(rig.cameras.size(), false) {
  for (const auto& camera : rig.cameras) cameraNames_.push_back(camera.name);
  if (config.calibrationWatch.intervalS <= 0) return;
  const processing::PanoramaSettings settings = panoramaSettings(config);
  std::vector<std::string> unseen;
  for (const auto& line : processing::seamLines(rig, settings)) {
    if (auto probe = processing::SeamMisalignmentProbe::make(rig, settings, line)) {
      seams_.push_back({std::move(*probe), std::nullopt});
    } else {
      unseen.push_back(line.name);
    }
  }
  if (!unseen.empty()) {
    spdlog::info(
        "calibration watch: no ground under seam {} that both its cameras see; not "
        "watched",
        fmt::join(unseen, ", "));
  }
}

void CalibrationWatchStage::process(FrameWork& work, StageTimes& times) {
  if (seams_.empty()) return;
  if (next_ && work.streamTime < *next_) return;
  next_ = work.streamTime + interval_;
  for (Seam& seam : seams_) {
    const auto& line = seam.probe.seam();
    const cv::Mat* left = work.bgr(line.left);
    const cv::Mat* right = work.bgr(line.right);
    // A camera missing from the set, or faulty (black, frozen), says nothing of the calibration.
    if (left == nullptr || right == nullptr || work.faults[line.left] != nullptr ||
        work.faults[line.right] != nullptr) {
      continue;
    }
    const auto measured = seam.probe.measure(*left, *right);
    if (measured.response >= kMinResponse) seam.last = measured;
  }
  judge();
  times.lap(Stage::kWatch);
}

std::vector<bool> driftingCameras(std::size_t cameras, std::span<const SeamShift> seams,
                                  double thresholdCm) {
  std::vector<bool> drifting(cameras, false);
  for (std::size_t camera = 0; camera < cameras; ++camera) {
    bool any = false;
    bool all = true;
    for (const SeamShift& seam : seams) {
      if (seam.left != camera && seam.right != camera) continue;
      any = true;
      all = all && seam.shiftCm && *seam.shiftCm > thresholdCm;
    }
    drifting[camera] = any && all;
  }
  return drifting;
}

void CalibrationWatchStage::judge() {
  std::vector<SeamShift> shifts;
  for (const Seam& seam : seams_) {
    shifts.push_back({seam.probe.seam().left, seam.probe.seam().right,
                      seam.last ? std::optional(seam.last->shiftCm) : std::nullopt});
  }
  const std::vector<bool> verdicts = driftingCameras(drifting_.size(), shifts, thresholdCm_);
  for (std::size_t camera = 0; camera < drifting_.size(); ++camera) {
    if (verdicts[camera] == drifting_[camera]) continue;
    drifting_[camera] = verdicts[camera];
    if (!verdicts[camera]) {
      spdlog::info("calibration watch: camera '{}' agrees with its neighbours again",
                   cameraNames_[camera]);
      continue;
    }
    std::vector<std::string> evidence;
    for (const Seam& seam : seams_) {
      const auto& line = seam.probe.seam();
      if (line.left == camera || line.right == camera) {
        evidence.push_back(fmt::format("{:.1f} cm at {}", seam.last->shiftCm, line.name));
      }
    }
    spdlog::warn(
        "calibration watch: camera '{}' is drifting: the ground under its seams is {} "
        "apart (more than {:g} cm); check its mount, then calibrate it again",
        cameraNames_[camera], fmt::join(evidence, ", "), thresholdCm_);
  }
}

void CalibrationWatchStage::report(PipelineReport& report) const {
  for (const Seam& seam : seams_) {
    SeamReport& measured = report.seams.emplace_back();
    measured.name = seam.probe.seam().name;
    measured.distanceM = seam.probe.distanceM();
    if (seam.last) {
      measured.shiftCm = seam.last->shiftCm;
      measured.response = seam.last->response;
      measured.misaligned = seam.last->shiftCm > thresholdCm_;
    }
  }
  for (std::size_t c = 0; c < report.cameras.size() && c < drifting_.size(); ++c) {
    report.cameras[c].calibrationDrifting = drifting_[c];
  }
}

}  // namespace surroundd::daemon
