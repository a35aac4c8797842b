#pragma once
// The guided mat calibration's state (surround-calibrate guide --mat): the newest picture of each
// camera in; out, every camera's mount solved from the calibration mat's boards it sees
// (processing::calibrateFromMat), the seam error between neighbours on the boards they share,
// the verdict against the limits, what to fix in words, and a stitched top view of the ground
// through the solved mounts. No threads, no I/O: the live page and the tests drive it alike.
//
// A solve runs once every camera has a picture newer than the last solve's: a live rig looking
// at a mat that someone straightens is solved again with each round of pictures, until it
// passes; then the session is done and the mounts are final.

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/ground_top_view.hpp"
#include "processing/calibration/mat_calibration.hpp"

namespace surroundd::calibrate {

struct MatGuideSettings {
  processing::MatLayout mat;
  // The cameras the mat names, with their lens and the mount assumed so far (the rig's).
  std::vector<processing::CameraCalibration> cameras;
  processing::MatLimits limits;  // limits.maxSeamCm: the seam verdict's threshold
  processing::MatDetectionSettings detection;
  processing::ExtrinsicSettings solve;
  int topViewSidePx = 560;  // the stitched top view's longer side
};

class MatGuideSession {
 public:
  // Throws processing::CalibrationError when a board names a camera that is not in `cameras`.
  explicit MatGuideSession(MatGuideSettings settings);

  // Camera `camera`'s newest picture (8-bit BGR, its lens's size); kept until the next one.
  // Solves when it completes a round; true when it did.
  bool offer(std::size_t camera, const cv::Mat& bgr);

  const MatGuideSettings& settings() const { return settings_; }
  const std::vector<cv::Mat>& pictures() const { return pictures_; }  // empty: none yet
  const std::vector<int>& framesOffered() const { return frames_; }
  const std::optional<processing::MatCalibration>& result() const { return result_; }
  std::size_t solves() const { return solves_; }
  bool passed() const { return result_ && result_->passed(); }
  // What to do next, in words: the cameras still without a picture, or what failed.
  std::vector<std::string> hints() const;
  // The ground around the car as the last solve's mounts stitch it (a camera without a solved
  // mount: its assumed one), cameras averaged where they overlap; empty before the first solve.
  const cv::Mat& topView() const { return topView_; }
  const processing::GroundGrid& topViewGrid() const { return grid_; }

 private:
  void solve();

  MatGuideSettings settings_;
  processing::GroundGrid grid_;
  std::vector<cv::Mat> pictures_;
  std::vector<int> frames_;
  std::vector<bool> fresh_;  // a picture since the last solve
  std::optional<processing::MatCalibration> result_;
  std::size_t solves_ = 0;
  cv::Mat topView_;
};

}  // namespace surroundd::calibrate
