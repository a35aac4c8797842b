#pragma once
// Small corrections to the cameras' mounts, found from the road: where two neighbouring cameras
// see the same ground, each puts it where its calibration says; a mount that is off puts it
// elsewhere. Ground patches laid over every overlap (overlap_patches.hpp) are compared by phase
// correlation (seam_misalignment.hpp's probe), set after set while the car moves; each
// comparison that means something (a clear correlation peak: ground with texture that both views
// show alike) becomes one match, the two rays that see the same ground point. A least-squares
// fit then turns each camera about its centre (three angles) and moves it up or down, so that
// every match's two rays meet the ground at one point.
//
// The reference: seams tie cameras only to each other, so one camera is held. Cameras are knocked
// one at a time, so the fit is made holding each camera in turn: holding a knocked camera leaves
// the seams apart, and of the fits that bring them together alike the one that turns the others
// least wins: a knocked front camera is corrected, not the three that agree. (The
// rig's mean would spread one knocked camera's error over all four.)
//
// Robustness: a patch whose views differ by more than a shift (a passing car, a kerb, anything
// above the ground) correlates poorly and is not a match; matches that still disagree with the
// fit (Huber's weights, then those past four times the residuals' robust spread) are left out.
// Heights come out only as far as the seams see them (the uncertainty says it); a weak prior
// (5 degrees, 2 cm) keeps what no seam sees at no correction. A correction is conclusive only
// where its uncertainty is a small part of a degree: a rig whose cameras share only far ground
// (narrow lenses: the paper's rig overlaps 8 m out and more) gets none.
//
// Errors: none thrown; solve() says when there is not enough ground yet.

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/seam_misalignment.hpp"
#include "processing/rig.hpp"

namespace surroundd::processing {

// One camera's correction: turn it by `rotationRad` (a rotation vector in the vehicle frame,
// about the camera's centre) and raise it by `heightM`.
struct MountCorrection {
  cv::Vec3d rotationRad;
  double heightM = 0;
  cv::Vec3d rotationSigmaRad;  // one standard deviation of each component; zero: held
  double heightSigmaM = 0;

  double angleDeg() const;  // how far it turns the camera
  // Its uncertainty small enough to act on (every angle within kConclusiveSigmaDeg); the held
  // camera's is.
  bool conclusive() const;
  static constexpr double kConclusiveSigmaDeg = 0.1;
  Pose applied(const Pose& pose) const;
};

// The mount angles' change between two poses of one camera, degrees (yaw wrapped to +-180).
MountAngles mountAngleChange(const Pose& before, const Pose& after);

// How far apart the seam's two cameras put the same ground (median over its fine patches'
// matches, else all of its matches), before and after the corrections.
struct SeamFit {
  std::string name;
  std::size_t left = 0, right = 0;  // its cameras
  std::size_t matches = 0;
  double beforeCm = 0;
  double afterCm = 0;

  bool touches(std::size_t camera) const { return left == camera || right == camera; }
};

// What to do with one camera's correction; only kOffered is one to make (refine writes it, the
// watch suggests it).
enum class CorrectionVerdict {
  kHeld,        // the camera the others were fitted around
  kUncertain,   // not conclusive()
  kTooLarge,    // past kLargestTurnDeg: a fault to report, not a correction to make
  kTooSmall,    // under kSmallestTurnDeg
  kSeamsApart,  // it would not close every seam the camera touches (closesSeams())
  kOffered,
};

struct MountRefinementResult {
  std::size_t reference = 0;  // the camera held
  std::vector<MountCorrection> cameras;
  std::vector<SeamFit> seams;
  std::size_t matches = 0;   // used
  std::size_t rejected = 0;  // left out as disagreeing with the fit
  std::size_t sets = 0;      // frame sets they came from (since the last follow())

  Rig corrected(const Rig& rig) const;
  // Whether the correction of `camera` brings every seam it touches together: each with
  // kMinMatches comparisons or more, closer than before, and within kClosedCm. A fit that
  // cannot close them (a camera knocked further than the patches' reach, so that most of its
  // comparisons fail) is no correction to make.
  bool closesSeams(std::size_t camera) const;
  static constexpr double kClosedCm = 2.0;
  // A turn under kSmallestTurnDeg moves the ground 1.5 cm at 4 m, under what a seam shows, and
  // is as likely the lens's or the fit's own error (an exact simulator's rig fits 0.1-0.2
  // degrees off).
  // A turn past kLargestTurnDeg is no drift but a fault (a camera knocked off its mount, a mirror
  // folded): the patches were laid through the mounts as they were, and a picture that far off
  // wants the mount looked at, not followed.
  CorrectionVerdict verdict(std::size_t camera) const;
  static constexpr double kSmallestTurnDeg = 0.2;
  static constexpr double kLargestTurnDeg = 5.0;
};

class MountRefinement {
 public:
  // Matches beyond `capacity` replace the oldest: the fit follows the newest ground.
  MountRefinement(const Rig& rig, const PanoramaSettings& settings, std::size_t capacity = 4096);

  // One frame set's pictures (8-bit BGR, one per camera of the rig; null where missing): compares
  // every patch whose two cameras are there, keeps the matches. Returns how many it kept.
  std::size_t add(std::span<const cv::Mat* const> pictures);
  // The corrections that bring the matches together, warm-started from the last; none while
  // a camera has fewer than a few matches on its seams.
  std::optional<MountRefinementResult> solve();
  // The online cadence (the daemon's watch, the benchmark): add() the set, and every
  // `solveEvery` sets solve(); a solution that turns a camera kFollowDeg or more from the
  // mounts the patches were laid through is followed, and the next solve comes
  // kSetsAfterFollow sets later. Returns the solution when one was made.
  std::optional<MountRefinementResult> track(std::span<const cv::Mat* const> pictures,
                                             std::size_t solveEvery = 10);
  static constexpr double kFollowDeg = 0.2;
  static constexpr std::size_t kSetsAfterFollow = 3;

  // Lays the patches through the rig as `result` corrects it, so that later sets' patches line
  // up (their shifts small, more of them clear, and the correlation's bias at sub-pixel shifts
  // gone); the matches so far, made through mounts now known to be off, are dropped.
  // Corrections stay relative to the rig given at construction.
  void follow(const MountRefinementResult& result);

  std::size_t matches() const { return matches_.size(); }
  std::size_t patches() const { return patches_.size(); }
  const std::vector<SeamLine>& seams() const { return seams_; }

  // Each match needs a correlation peak this clear.
  static constexpr double kMinResponse = 0.15;
  // A camera takes part in a fit once its seams have this many matches.
  static constexpr std::size_t kMinMatches = 8;

 private:
  struct Match {
    std::size_t seam = 0;
    cv::Vec3d rayLeft, rayRight;  // camera frames, unit: the same ground seen by each camera
    double sigmaM = 0;            // how far off it may be: about a pixel of its patch
  };
  struct Fit;
  Fit fit(std::size_t reference, std::vector<double> start, bool trim) const;
  void layPatches(const Rig& through);
  std::vector<double> residuals(const std::vector<double>& parameters) const;

  Rig rig_;       // the calibration the corrections are to
  Rig patchRig_;  // the mounts the patches are laid through
  std::vector<SeamLine> seams_;
  std::vector<SeamMisalignmentProbe> patches_;
  std::vector<std::size_t> patchSeam_;  // per patch
  std::vector<Match> matches_;
  std::size_t capacity_;
  std::size_t oldest_ = 0;  // where the next match goes once at capacity
  std::size_t sets_ = 0;
  std::vector<double> warm_;               // the last fit's parameters, four per camera
  std::size_t sinceSolve_ = 0;             // track()'s
  std::vector<MountCorrection> followed_;  // what the patches are laid through
};

}  // namespace surroundd::processing
