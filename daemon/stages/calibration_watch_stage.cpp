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

void CalibrationWatchStage::process(FrameWork& work, StageTimes& /*times*/) {
  if (seams_.empty()) return;
  if (next_ && work.streamTime < *next_) return;
  next_ = work.streamTime + interval_;
  for (Seam& seam : seams_) {
    const auto& line = seam.probe.seam();
    const cv::Mat* left = work.images[line.left];
    const cv::Mat* right = work.images[line.right];
    // A camera missing from the set, or faulty (black, frozen), says nothing of the calibration.
    if (left == nullptr || right == nullptr || work.faults[line.left] != nullptr ||
        work.faults[line.right] != nullptr) {
      continue;
    }
    const auto measured = seam.probe.measure(*left, *right);
    if (measured.response >= kMinResponse) seam.last = measured;
  }
  judge();
}

void CalibrationWatchStage::judge() {
  for (std::size_t camera = 0; camera < drifting_.size(); ++camera) {
    std::vector<std::string> evidence;
    bool measured = false;
    bool allOff = true;
    for (const Seam& seam : seams_) {
      const auto& line = seam.probe.seam();
      if ((line.left != camera && line.right != camera) || !seam.last) continue;
      measured = true;
      if (seam.last->shiftCm > thresholdCm_) {
        evidence.push_back(fmt::format("{:.1f} cm at {}", seam.last->shiftCm, line.name));
      } else {
        allOff = false;
      }
    }
    const bool drifting = measured && allOff;
    if (drifting == drifting_[camera]) continue;
    drifting_[camera] = drifting;
    if (drifting) {
      spdlog::warn(
          "calibration watch: camera '{}' is drifting: the ground under its seams is "
          "{} apart (more than {:g} cm); check its mount, then calibrate it again",
          cameraNames_[camera], fmt::join(evidence, ", "), thresholdCm_);
    } else {
      spdlog::info("calibration watch: camera '{}' agrees with its neighbours again",
                   cameraNames_[camera]);
    }
  }
}

std::vector<SeamReport> CalibrationWatchStage::seams() const {
  std::vector<SeamReport> reports;
  for (const Seam& seam : seams_) {
    SeamReport report;
    report.name = seam.probe.seam().name;
    report.distanceM = seam.probe.distanceM();
    if (seam.last) {
      report.shiftCm = seam.last->shiftCm;
      report.response = seam.last->response;
      report.misaligned = seam.last->shiftCm > thresholdCm_;
    }
    reports.push_back(std::move(report));
  }
  return reports;
}

}  // namespace surroundd::daemon
