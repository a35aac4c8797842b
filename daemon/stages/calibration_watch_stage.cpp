#include "daemon/stages/calibration_watch_stage.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "daemon/config/panorama_setup.hpp"

namespace surroundd::daemon {

CalibrationWatchStage::CalibrationWatchStage(const Config& config, const processing::Rig& rig)
    : interval_(std::chrono::duration_cast<std::chrono::nanoseconds>(
          std::chrono::duration<double>(config.calibrationWatch.intervalS))),
      thresholdCm_(config.calibrationWatch.thresholdCm),
      drifting_(rig.cameras.size(), false),
      rig_(rig),
      compareEvery_(std::chrono::duration_cast<std::chrono::nanoseconds>(
          std::chrono::duration<double>(config.calibrationWatch.compareEveryS))),
      suggested_(rig.cameras.size()) {
  for (const auto& camera : rig.cameras) cameraNames_.push_back(camera.name);
  if (config.calibrationWatch.intervalS <= 0) return;
  const processing::PanoramaSettings settings = panoramaSettings(config);
  if (config.calibrationWatch.correct == CalibrationWatchConfig::Correct::kSuggest) {
    refinement_ = std::make_unique<MountCorrectionWorker>(rig, settings);
  }
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
  if (refinement_) offerToRefinement(work);
  if (seams_.empty() && !refinement_) return;
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
  if (refinement_) readSuggestions();
  times.lap(Stage::kWatch);
}

void CalibrationWatchStage::offerToRefinement(FrameWork& work) {
  // While the worker is busy no set's pictures are converted for it: the next one is offered.
  if ((nextCompare_ && work.streamTime < *nextCompare_) || !refinement_->idle()) return;
  std::array<const cv::Mat*, kMaxCameras> pictures{};
  for (std::size_t c = 0; c < rig_.cameras.size() && c < kMaxCameras; ++c) {
    // A faulty camera's picture (black, frozen) is no view of the ground.
    pictures[c] = work.faults[c] == nullptr ? work.bgr(c) : nullptr;
  }
  // Only this thread offers, so the worker found idle above takes it.
  if (refinement_->offer({pictures.data(), rig_.cameras.size()})) {
    nextCompare_ = work.streamTime + compareEvery_;
  }
}

void CalibrationWatchStage::readSuggestions() {
  latest_ = refinement_->latest();
  if (!latest_.result) return;
  const processing::MountRefinementResult& result = *latest_.result;
  for (std::size_t c = 0; c < suggested_.size(); ++c) {
    const processing::MountCorrection& correction = result.cameras[c];
    std::optional<MountSuggestion> now;
    const processing::CorrectionVerdict verdict = result.verdict(c);
    if (verdict == processing::CorrectionVerdict::kOffered ||
        verdict == processing::CorrectionVerdict::kTooLarge) {
      const cv::Vec3d sigma = correction.rotationSigmaRad * (180 / std::numbers::pi);
      const processing::Pose& pose = rig_.cameras[c].pose;
      now = MountSuggestion{processing::mountAngleChange(pose, correction.applied(pose)),
                            100 * correction.heightM, std::max({sigma[0], sigma[1], sigma[2]}),
                            verdict == processing::CorrectionVerdict::kTooLarge};
    }
    const auto turned = [](const std::optional<MountSuggestion>& s) {
      return s ? std::abs(s->changeDeg.yawDeg) + std::abs(s->changeDeg.pitchDeg) +
                     std::abs(s->changeDeg.rollDeg)
               : 0.0;
    };
    // Logged when a suggestion appears, goes, or moves by a tenth of a degree or more.
    const bool changed = now.has_value() != suggested_[c].has_value() ||
                         (now && (now->fault != suggested_[c]->fault ||
                                  std::abs(turned(now) - turned(suggested_[c])) >= 0.1));
    if (!changed) continue;
    suggested_[c] = now;
    if (!now) {
      spdlog::info("calibration watch: camera '{}' needs no correction now", cameraNames_[c]);
      continue;
    }
    if (now->fault) {
      spdlog::error(
          "calibration watch: camera '{}' has turned yaw {:+.1f}°, pitch {:+.1f}°, roll {:+.1f}° "
          "(±{:.2f}°): more than the {:g}° a mount correction may make; check its mount",
          cameraNames_[c], now->changeDeg.yawDeg, now->changeDeg.pitchDeg, now->changeDeg.rollDeg,
          now->sigmaDeg, processing::MountRefinementResult::kLargestTurnDeg);
      continue;
    }
    std::vector<std::string> before;
    std::vector<std::string> after;
    for (const processing::SeamFit& seam : result.seams) {
      if (!seam.touches(c)) continue;
      before.push_back(fmt::format("{:.1f}", seam.beforeCm));
      after.push_back(fmt::format("{:.1f}", seam.afterCm));
    }
    spdlog::warn(
        "calibration watch: camera '{}': yaw {:+.1f}°, pitch {:+.1f}°, roll {:+.1f}° "
        "(±{:.2f}°) would bring its seams from {} to {} cm (from {} sets); surround-calibrate "
        "refine --update-rig writes it",
        cameraNames_[c], now->changeDeg.yawDeg, now->changeDeg.pitchDeg, now->changeDeg.rollDeg,
        now->sigmaDeg, fmt::join(before, " / "), fmt::join(after, " / "), result.sets);
  }
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
    report.cameras[c].mountSuggestion = suggested_[c];
  }
  if (!refinement_) return;
  // The counts as they are now; the suggestions and seams as last judged.
  const MountCorrectionState now = refinement_->latest();
  report.mountWatch =
      MountWatchReport{now.setsCompared, now.result ? now.result->matches : 0, now.cpuSeconds};
  if (!latest_.result) return;
  for (SeamReport& seam : report.seams) {
    for (const processing::SeamFit& fit : latest_.result->seams) {
      if (fit.name == seam.name && fit.matches > 0) seam.suggestedCm = fit.afterCm;
    }
  }
}

}  // namespace surroundd::daemon
