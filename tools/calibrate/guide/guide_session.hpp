#pragma once
// The guided intrinsics calibration's state machine (surround-calibrate guide): camera frames
// in, one at a time; out, what each frame did (a view accepted, or why not), the views kept, the
// coverage map they fill, what is still missing in words, and the verdict once there is enough
// to solve. No threads, no I/O: the live page and the tests drive it alike.
//
// A frame's board becomes a view when it is found, sharp (edgeWidthPx within the limits) and not
// a repeat of a view already kept (its outline overlaps one by at least `repeatOverlap`: a board
// held still gives one view, not thirty). Once `limits.minViews` views and `limits.minCoverage`
// are there, every new view solves again (calibrateLeavingOutBadViews, judgeCalibration, and the
// guide's precision limits) until it passes; then the session is done and takes no more views.

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/calibration_board.hpp"
#include "processing/calibration/calibration_coverage.hpp"
#include "processing/calibration/calibration_verdict.hpp"
#include "processing/calibration/intrinsic_calibration.hpp"

namespace surroundd::calibrate {

struct GuideSettings {
  processing::CalibrationBoard board;
  processing::LensModel model = processing::LensModel::kPinhole;
  processing::CalibrationLimits limits;
  // Intersection over union of two board outlines from which a new view repeats a kept one.
  // Lower than the picture folder's 0.95: a live camera sees the board drift a little while it
  // is held, and a guide wants views that add something.
  double repeatOverlap = 0.7;
  std::optional<double> fieldOfViewDeg;  // fisheye: as --field-of-view-deg
};

// A guide solves as soon as it may, so it asks more of the solve's own uncertainty than a folder
// of pictures is asked (CalibrationLimits): a few views that all lean the same way fit to a tenth
// of a pixel and still leave the focal length a percent off; these are what keep such a solve
// from passing. The session holds its limits to them at most.
inline constexpr double kGuideFocalSdPercent = 0.1;
inline constexpr double kGuidePrincipalSdPx = 0.3;

enum class FrameOutcome {
  kAccepted,         // a new view was kept
  kNoBoard,          // no board in the picture
  kLargerThanBoard,  // a larger chessboard grid than the one named: the board size is wrong
  kBlurred,          // found, but its edges are wider than limits.maxEdgeWidthPx
  kRepeat,           // found, but where a kept view already is
  kDone,             // the session has passed; frames are only shown
};

struct FrameResult {
  FrameOutcome outcome = FrameOutcome::kNoBoard;
  std::vector<cv::Point2f> corners;  // where the board was found (for drawing), if it was
  std::string note;                  // one sentence for the page: why, or what was kept
};

struct GuideView {
  processing::BoardView view;  // name: "view N"
  std::chrono::nanoseconds streamTime{0};
};

struct GuideSolve {
  processing::IntrinsicCalibration result;  // its lens limited to the field of view
  processing::Verdict verdict;
  processing::FieldOfView field;
  std::vector<std::string> leftOut;  // views the solve dropped, "name: RMS x px"
  std::size_t viewsOffered = 0;      // views kept when it ran
};

class GuideSession {
 public:
  explicit GuideSession(const GuideSettings& settings);

  // `gray`: CV_8U, every frame the same size; `streamTime`: the frame's time from the start of
  // the stream. Solves when the view it keeps makes enough. Throws std::invalid_argument when
  // the size changes (one camera, one resolution).
  FrameResult offer(const cv::Mat& gray, std::chrono::nanoseconds streamTime);

  const GuideSettings& settings() const { return settings_; }
  cv::Size imageSize() const { return imageSize_; }
  const std::vector<GuideView>& views() const { return views_; }
  const processing::CoverageMap& coverage() const { return coverage_; }
  // What to do next, in words: where the board has not been yet, or why the solve failed.
  std::vector<std::string> hints() const;
  const std::optional<GuideSolve>& lastSolve() const { return solve_; }
  bool passed() const { return solve_ && solve_->verdict.passed; }
  std::chrono::nanoseconds passedAt() const { return passedAt_; }  // stream time of the pass
  std::size_t framesOffered() const { return frames_; }
  // A larger grid was seen and no board yet: the message naming the size (empty otherwise).
  const std::string& boardSizeProblem() const { return sizeProblem_; }
  const cv::Mat& brightest() const { return brightest_; }  // CV_8U, per pixel over the frames

 private:
  void solve(std::chrono::nanoseconds streamTime);
  bool enoughToSolve() const;

  GuideSettings settings_;
  cv::Size imageSize_;
  cv::Mat brightest_;
  processing::ImageCircle circle_;
  std::vector<GuideView> views_;
  processing::CoverageMap coverage_;
  std::optional<GuideSolve> solve_;
  std::chrono::nanoseconds passedAt_{0};
  std::size_t frames_ = 0;
  std::string sizeProblem_;
};

}  // namespace surroundd::calibrate
