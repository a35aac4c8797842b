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
// With calibration_watch.correct: suggest, every compare_every_s the set's pictures also go to the
// mount refinement on its own thread (mount_correction_worker.hpp); at each measurement the
// latest solution is read, and a camera whose correction is worth applying (conclusive, 0.2
// degrees or more, closing every seam it touches) is reported and logged with what it would do to
// its seams. Nothing is changed: surround-calibrate refine --update-rig writes a correction into
// the rig.

#include <chrono>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "daemon/config/config.hpp"
#include "daemon/pipeline_report.hpp"
#include "daemon/pipeline_stage.hpp"
#include "daemon/stages/mount_correction_worker.hpp"
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

class CalibrationWatchStage final : public PipelineStage {
 public:
  // Correlation peaks below this say the ground has too little texture to be compared.
  static constexpr double kMinResponse = 0.1;

  CalibrationWatchStage(const Config& config, const processing::Rig& rig);

  void process(FrameWork& work, StageTimes& times) override;
  // Each seam's last measurement (none before the first, or where the ground could not be
  // compared), and each camera's verdict.
  void report(PipelineReport& report) const override;

 private:
  struct Seam {
    processing::SeamMisalignmentProbe probe;
    std::optional<processing::SeamMisalignment> last;  // with a response of kMinResponse or more
  };
  void judge();
  void offerToRefinement(FrameWork& work);
  void readSuggestions();

  std::vector<std::string> cameraNames_;
  std::vector<Seam> seams_;
  std::chrono::nanoseconds interval_;
  std::optional<std::chrono::nanoseconds> next_;  // stream time of the next measurement
  double thresholdCm_;
  std::vector<bool> drifting_;  // per camera

  // correct: suggest
  std::unique_ptr<MountCorrectionWorker> refinement_;
  processing::Rig rig_;  // the mounts the suggestions turn
  std::chrono::nanoseconds compareEvery_{};
  std::optional<std::chrono::nanoseconds> nextCompare_;
  MountCorrectionState latest_;
  std::vector<std::optional<MountSuggestion>> suggested_;  // per camera, as last logged
};

}  // namespace surroundd::daemon
