#pragma once
// The calibration-drift watch: every calibration_watch.interval_s of stream time, how far apart
// each seam's two cameras put the ground under the seam (processing/calibration/
// seam_misalignment.hpp), measured on that set's frames. A seam past threshold_cm, with a
// correlation peak that means something, is misaligned; a camera whose seams are all measured and
// all misaligned is "calibration drifting" — a knocked mirror camera moves the ground under both
// its seams while its neighbours' other seams stay put. One misaligned seam alone cannot say which
// of its cameras moved: it is reported, no camera is named. Changes are logged; the pipeline's
// report carries each seam's figure and each camera's verdict.
//
// Its probes (where each camera sees each seam's ground patch) are made once at start-up; a
// measurement resamples only the patches (two of 160 x 160 pixels per seam) and correlates them.
//
// With calibration_watch.correct: suggest (or apply), every compare_every_s the set's pictures also
// go to the mount refinement on its own thread (mount_correction_worker.hpp); at each measurement
// the latest solution is read, and a camera whose correction is worth applying (conclusive, 0.2
// degrees or more, closing every seam it touches) is reported and logged with what it would do to
// its seams. With suggest nothing is changed: surround-calibrate refine --update-rig writes a
// correction into the rig.
//
// With correct: apply, a correction worth applying in two solutions in a row
// (processing/calibration/agreed_corrections.hpp) is also made: the panorama stage builds its
// table for the corrected mounts beside the sets and switches at a set boundary
// (PanoramaStage::remount()); the watch's probes and the refinement start again from those mounts.
// Then the watch checks the correction on its next kChecks measurements: a seam it touches that
// comes out worse than before it (by kWorseCm) or still past threshold_cm means it did not hold,
// and the mounts go back as they were; the watch then only suggests until the daemon starts again.
// A camera turned past MountRefinementResult::kLargestTurnDeg is a fault, never corrected.

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "daemon/config/config.hpp"
#include "daemon/mount_corrections.hpp"
#include "daemon/pipeline_report.hpp"
#include "daemon/pipeline_stage.hpp"
#include "daemon/stages/mount_correction_worker.hpp"
#include "daemon/stages/panorama_stage.hpp"
#include "processing/calibration/agreed_corrections.hpp"
#include "processing/calibration/seam_misalignment.hpp"
#include "processing/rig.hpp"

namespace surroundd::daemon {

// One seam as the verdict sees it: its cameras, and its last shift where it was measured.
struct SeamShift {
  std::size_t left = 0, right = 0;
  std::optional<double> shiftCm;
};
// Per camera of `cameras`: whether its seams are all measured and all past `thresholdCm`.
std::vector<bool> driftingCameras(std::size_t cameras, std::span<const SeamShift> seams,
                                  double thresholdCm);

// A seam an applied correction touched: its shift before, and those measured since.
struct SeamCheck {
  std::optional<double> beforeCm;
  std::vector<double> afterCm;
};
// Whether a correction held: every seam it touched that was measured since comes out (the median
// of its measurements) no more than `worseCm` above what it was before and within `thresholdCm`.
bool correctionHeld(std::span<const SeamCheck> seams, double thresholdCm, double worseCm);

class CalibrationWatchStage final : public PipelineStage, public MountCorrections {
 public:
  // Correlation peaks below this say the ground has too little texture to be compared.
  static constexpr double kMinResponse = 0.1;

  // Measurements after an applied correction that decide whether it held.
  static constexpr int kChecks = 3;
  // How much worse than before a seam may come out after a correction: the probes' own scatter
  // (on the generated drive one seam measures 0.3 cm in some stretches and 1.6 cm in others with
  // the mounts unchanged); 2 cm is 0.3 degrees at the seams' 4 m.
  static constexpr double kWorseCm = 2.0;

  // Watches the seams of `panorama`'s rig, which must outlive the stage; correct: apply remounts
  // it.
  CalibrationWatchStage(const Config& config, PanoramaStage& panorama);

  void process(FrameWork& work, StageTimes& times) override;
  // Each seam's last measurement (none before the first, or where the ground could not be
  // compared), and each camera's verdict.
  void report(PipelineReport& report) const override;

  // MountCorrections (daemon/mount_corrections.hpp).
  std::vector<std::pair<std::string, processing::Pose>> correctedMounts() const override;
  void accepted() override { kept_ = rig_; }
  std::string revert() override;

 private:
  struct Seam {
    processing::SeamMisalignmentProbe probe;
    std::optional<processing::SeamMisalignment> last;  // with a response of kMinResponse or more
    bool fresh = false;                                // `last` is the latest measurement's
    // The last kChecks measurements' shifts, oldest first: what a correction's check compares
    // with (their median: one set's figure can be a passing car's).
    std::vector<double> recentCm;
  };
  // The probes of the seams of rig_ (and the refinement's worker with correct: suggest or apply).
  void watchSeams();
  // Takes up the panorama's new mounts once it has switched to them: the probes and the
  // refinement start again from them, and an applied correction's check begins.
  void followRemount();
  void judge();
  void offerToRefinement(FrameWork& work);
  void readSuggestions();
  // correct: apply: makes the corrections a new solution agrees on with the one before.
  void considerApplying();
  // correct: apply: adds this measurement to the check of the correction applied, and goes back
  // to the mounts before it once the check finds it did not hold.
  void checkApplied();

  PanoramaStage& panorama_;
  processing::PanoramaSettings settings_;
  std::vector<std::string> cameraNames_;
  std::vector<Seam> seams_;
  std::chrono::nanoseconds interval_;
  std::optional<std::chrono::nanoseconds> next_;  // stream time of the next measurement
  double thresholdCm_;
  std::vector<bool> drifting_;  // per camera

  // correct: suggest or apply
  bool suggest_;
  std::unique_ptr<MountCorrectionWorker> refinement_;
  processing::Rig rig_;       // the mounts the suggestions turn: the panorama's
  processing::Rig kept_;      // the run's start, or the last accepted
  std::uint64_t generation_;  // of the panorama's tables rig_ is
  std::chrono::nanoseconds compareEvery_{};
  std::optional<std::chrono::nanoseconds> nextCompare_;
  MountCorrectionState latest_;
  std::vector<std::optional<MountSuggestion>> suggested_;  // per camera, as last logged

  // correct: apply
  struct Applied {
    std::vector<std::size_t> cameras;  // corrected
    processing::Rig before;            // the mounts to go back to
    std::vector<SeamCheck> seams;      // per seam of seams_; empty until switched to
  };
  bool apply_;
  std::optional<Applied> applied_;  // applied, and being checked (or switched to)
  int checked_ = 0;                 // measurements since the switch
  std::size_t solutionsSeen_ = 0;
  processing::AgreedCorrections agreed_;
  bool applyHalted_ = false;  // a correction did not hold: suggestions only
  std::size_t appliedCount_ = 0, revertedCount_ = 0;
};

}  // namespace surroundd::daemon
