#include "daemon/stages/calibration_watch_stage.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "daemon/config/panorama_setup.hpp"
#include "processing/calibration/view_acceptance.hpp"

namespace surroundd::daemon {

CalibrationWatchStage::CalibrationWatchStage(const Config& config, PanoramaStage& panorama)
    : panorama_(panorama),
      settings_(panoramaSettings(config)),
      interval_(std::chrono::duration_cast<std::chrono::nanoseconds>(
          std::chrono::duration<double>(config.calibrationWatch.intervalS))),
      thresholdCm_(config.calibrationWatch.thresholdCm),
      drifting_(panorama.rig().cameras.size(), false),
      suggest_(config.calibrationWatch.intervalS > 0 &&
               config.calibrationWatch.correct != CalibrationWatchConfig::Correct::kOff),
      rig_(panorama.rig()),
      kept_(rig_),
      generation_(panorama.generation()),
      compareEvery_(std::chrono::duration_cast<std::chrono::nanoseconds>(
          std::chrono::duration<double>(config.calibrationWatch.compareEveryS))),
      suggested_(rig_.cameras.size()),
      apply_(suggest_ &&
             config.calibrationWatch.correct == CalibrationWatchConfig::Correct::kApply) {
  for (const auto& camera : rig_.cameras) cameraNames_.push_back(camera.name);
  if (config.calibrationWatch.intervalS <= 0) return;
  watchSeams();
}

void CalibrationWatchStage::watchSeams() {
  // The worker first: its thread is joined, with any comparison under way, before the new one.
  refinement_.reset();
  if (suggest_) refinement_ = std::make_unique<MountCorrectionWorker>(rig_, settings_);
  seams_.clear();
  std::vector<std::string> unseen;
  for (const auto& line : processing::seamLines(rig_, settings_)) {
    if (auto probe = processing::SeamMisalignmentProbe::make(rig_, settings_, line)) {
      seams_.push_back({std::move(*probe), std::nullopt, false, {}});
      seams_.back().recentCm.reserve(kChecks);
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

void CalibrationWatchStage::followRemount() {
  if (panorama_.generation() == generation_) {
    if (applied_ && applied_->seams.empty() && !panorama_.remounting()) {
      // The panorama could not be made through the corrected mounts (it said why).
      applied_.reset();
      applyHalted_ = true;
    }
    return;
  }
  generation_ = panorama_.generation();
  rig_ = panorama_.rig();
  // Measured through the old mounts: the shifts, the matches and the suggestions.
  std::vector<std::optional<double>> before;
  for (const Seam& seam : seams_) {
    before.push_back(seam.recentCm.empty() ? std::nullopt
                                           : std::optional(processing::median(seam.recentCm)));
  }
  watchSeams();
  latest_ = {};
  solutionsSeen_ = 0;
  std::ranges::fill(suggested_, std::nullopt);
  agreed_.clear();
  next_.reset();
  nextCompare_.reset();
  if (!applied_) return;
  ++appliedCount_;
  if (seams_.empty()) {
    spdlog::warn(
        "calibration watch: the panorama shows the corrected mounts; no seam can check "
        "them");
    applied_.reset();
    return;
  }
  // seamLines() of the same cameras: the same seams, in the same order.
  applied_->seams.assign(seams_.size(), {});
  for (std::size_t i = 0; i < seams_.size() && i < before.size(); ++i) {
    applied_->seams[i].beforeCm = before[i];
  }
  spdlog::info(
      "calibration watch: the panorama shows the corrected mounts; checking them over "
      "the next {} measurements",
      kChecks);
}

void CalibrationWatchStage::process(FrameWork& work, StageTimes& times) {
  followRemount();
  if (refinement_) offerToRefinement(work);
  if (seams_.empty() && !refinement_) return;
  if (next_ && work.streamTime < *next_) return;
  next_ = work.streamTime + interval_;
  for (Seam& seam : seams_) {
    seam.fresh = false;
    const auto& line = seam.probe.seam();
    const cv::Mat* left = work.bgr(line.left);
    const cv::Mat* right = work.bgr(line.right);
    // A camera missing from the set, or faulty (black, frozen), says nothing of the calibration.
    if (left == nullptr || right == nullptr || work.faults[line.left] != nullptr ||
        work.faults[line.right] != nullptr) {
      continue;
    }
    const auto measured = seam.probe.measure(*left, *right);
    if (measured.response >= kMinResponse) {
      seam.last = measured;
      seam.fresh = true;
      if (seam.recentCm.size() == kChecks) seam.recentCm.erase(seam.recentCm.begin());
      seam.recentCm.push_back(measured.shiftCm);
    }
  }
  judge();
  if (applied_ && !applied_->seams.empty()) checkApplied();
  if (refinement_) readSuggestions();
  if (apply_ && !applyHalted_ && !applied_) considerApplying();
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
        "(±{:.2f}°) would bring its seams from {} to {} cm (from {} sets){}",
        cameraNames_[c], now->changeDeg.yawDeg, now->changeDeg.pitchDeg, now->changeDeg.rollDeg,
        now->sigmaDeg, fmt::join(before, " / "), fmt::join(after, " / "), result.sets,
        apply_ && !applyHalted_ ? "" : "; surround-calibrate refine --update-rig writes it");
  }
}

void CalibrationWatchStage::considerApplying() {
  if (!latest_.result || latest_.solutions == solutionsSeen_ || panorama_.remounting()) return;
  solutionsSeen_ = latest_.solutions;
  const processing::MountRefinementResult& result = *latest_.result;
  const std::vector<std::size_t> agreed = agreed_.add(result, rig_);
  if (agreed.empty()) return;
  Applied applied{agreed, rig_, {}};
  processing::Rig corrected = rig_;
  std::vector<std::string> names;
  for (const std::size_t c : agreed) {
    corrected.cameras[c].pose = result.cameras[c].applied(rig_.cameras[c].pose);
    names.push_back(fmt::format("'{}'", cameraNames_[c]));
  }
  spdlog::warn(
      "calibration watch: correcting camera {} as suggested (two solutions in a row "
      "agree); the panorama's table for the corrected mounts is built beside the sets",
      fmt::join(names, ", "));
  panorama_.remount(std::move(corrected));
  applied_ = std::move(applied);
}

void CalibrationWatchStage::checkApplied() {
  Applied& applied = *applied_;
  std::vector<SeamCheck> touched;
  // Every seam it touched measured kChecks times; or, where one's ground will not compare, the
  // others after 3 x kChecks measurements.
  int fewest = kChecks;
  for (std::size_t i = 0; i < seams_.size(); ++i) {
    const auto& line = seams_[i].probe.seam();
    const bool touches = std::ranges::any_of(
        applied.cameras, [&](std::size_t c) { return line.left == c || line.right == c; });
    if (!touches) continue;
    if (seams_[i].fresh) applied.seams[i].afterCm.push_back(seams_[i].last->shiftCm);
    fewest = std::min(fewest, static_cast<int>(applied.seams[i].afterCm.size()));
    touched.push_back(applied.seams[i]);
  }
  ++checked_;
  if (fewest < kChecks && checked_ < 3 * kChecks) return;
  checked_ = 0;
  std::vector<std::string> names;
  for (const std::size_t c : applied.cameras) names.push_back(fmt::format("'{}'", cameraNames_[c]));
  if (correctionHeld(touched, thresholdCm_, kWorseCm)) {
    spdlog::info("calibration watch: the correction of camera {} holds", fmt::join(names, ", "));
    applied_.reset();
    return;
  }
  std::vector<std::string> figures;
  for (const SeamCheck& seam : touched) {
    if (seam.afterCm.empty()) continue;
    figures.push_back(fmt::format(
        "{:.1f} cm after, {} before", processing::median(seam.afterCm),
        seam.beforeCm ? fmt::format("{:.1f} cm", *seam.beforeCm) : std::string("not measured")));
  }
  spdlog::error(
      "calibration watch: the correction of camera {} did not hold (its seams: {}): "
      "back to the mounts before it; corrections are only suggested from now on",
      fmt::join(names, ", "), fmt::join(figures, "; "));
  panorama_.remount(std::move(applied.before));
  applied_.reset();
  applyHalted_ = true;
  ++revertedCount_;
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

std::vector<std::pair<std::string, processing::Pose>> CalibrationWatchStage::correctedMounts()
    const {
  std::vector<std::pair<std::string, processing::Pose>> mounts;
  for (std::size_t c = 0; c < rig_.cameras.size(); ++c) {
    const processing::Pose& now = rig_.cameras[c].pose;
    const processing::Pose& kept = kept_.cameras[c].pose;
    if (now.rotation != kept.rotation || now.position != kept.position) {
      mounts.emplace_back(cameraNames_[c], now);
    }
  }
  return mounts;
}

std::string CalibrationWatchStage::revert() {
  std::set<std::string> names;  // the corrected, and those being corrected
  for (const auto& mount : correctedMounts()) names.insert(fmt::format("'{}'", mount.first));
  if (applied_) {
    for (const std::size_t c : applied_->cameras)
      names.insert(fmt::format("'{}'", cameraNames_[c]));
  }
  applyHalted_ = apply_;
  applied_.reset();
  if (names.empty()) {
    return "the panorama shows the mounts the run started with (or last accepted): nothing to "
           "take back\n";
  }
  spdlog::warn(
      "calibration watch: the corrections of camera {} taken back on request; "
      "corrections are only suggested from now on",
      fmt::join(names, ", "));
  panorama_.remount(kept_);
  ++revertedCount_;
  return fmt::format(
      "going back to the mounts the run started with (or last accepted) for camera "
      "{}; corrections are only suggested from now on\n",
      fmt::join(names, ", "));
}

bool correctionHeld(std::span<const SeamCheck> seams, double thresholdCm, double worseCm) {
  return std::ranges::all_of(seams, [&](const SeamCheck& seam) {
    if (seam.afterCm.empty()) return true;  // not measured since: no evidence either way
    const double after = processing::median(seam.afterCm);
    return after <= thresholdCm && (!seam.beforeCm || after <= *seam.beforeCm + worseCm);
  });
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
  report.mountWatch = MountWatchReport{.setsCompared = now.setsCompared,
                                       .comparisons = now.result ? now.result->matches : 0,
                                       .cpuSeconds = now.cpuSeconds,
                                       .applying = apply_,
                                       .applied = appliedCount_,
                                       .reverted = revertedCount_,
                                       .checking = applied_.has_value()};
  if (!latest_.result) return;
  for (SeamReport& seam : report.seams) {
    for (const processing::SeamFit& fit : latest_.result->seams) {
      if (fit.name == seam.name && fit.matches > 0) seam.suggestedCm = fit.afterCm;
    }
  }
}

}  // namespace surroundd::daemon
