#include "processing/calibration/mount_refinement.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include <opencv2/calib3d.hpp>

#include "processing/calibration/overlap_patches.hpp"

namespace surroundd::processing {
namespace {

constexpr double kDegree = std::numbers::pi / 180;
constexpr std::size_t kPerCamera = 4;  // three angles, the height
constexpr double kMatchSigmaM = 0.01;  // a patch's shift is good to about a pixel
constexpr double kHuber = 3;           // past this many of its spreads a match weighs less
constexpr double kAnglePriorRad = 5 * kDegree;
constexpr double kHeightPriorM = 0.02;
constexpr double kStep = 1e-6;  // numerical derivatives
constexpr int kIterations = 30;
constexpr double kAlikeCost = 1.25;  // fits within this factor of the best bring the seams alike

cv::Matx33d turn(const cv::Vec3d& rotation) {
  cv::Matx33d matrix;
  cv::Rodrigues(rotation, matrix);
  return matrix;
}

// Where a camera at `position`, turned by `rotation`, sees the ground along its camera-frame
// `ray`; NaN where it does not.
cv::Vec2d groundHit(const cv::Matx33d& rotation, const cv::Vec3d& position, const cv::Vec3d& ray) {
  const cv::Vec3d d = rotation * ray;
  if (d[2] > -1e-9) return {std::nan(""), std::nan("")};
  const double t = -position[2] / d[2];
  return {position[0] + t * d[0], position[1] + t * d[1]};
}

// A camera's pose turned and raised by its four parameters, and, `nudged`, by each parameter
// nudged either way (for the derivatives): variant 0 is the pose, 1 + 2k and 2 + 2k parameter k
// +- kStep.
struct NudgedPose {
  std::array<cv::Matx33d, 2 * kPerCamera + 1> rotation;
  std::array<cv::Vec3d, 2 * kPerCamera + 1> position;

  NudgedPose(const Pose& pose, const double* p, bool nudged) {
    for (std::size_t v = 0; v < (nudged ? rotation.size() : 1); ++v) {
      std::array<double, kPerCamera> q{p[0], p[1], p[2], p[3]};
      if (v > 0) q[(v - 1) / 2] += (v % 2 == 1 ? kStep : -kStep);
      rotation[v] = turn({q[0], q[1], q[2]}) * pose.rotation;
      position[v] = pose.position + cv::Vec3d(0, 0, q[3]);
    }
  }
  cv::Vec2d hit(const cv::Vec3d& ray, std::size_t variant = 0) const {
    return groundHit(rotation[variant], position[variant], ray);
  }
};

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::ranges::nth_element(values, middle);
  return *middle;
}

}  // namespace

double MountCorrection::angleDeg() const { return cv::norm(rotationRad) / kDegree; }

bool MountCorrection::conclusive() const {
  const double largest = std::max({rotationSigmaRad[0], rotationSigmaRad[1], rotationSigmaRad[2]});
  return largest <= kConclusiveSigmaDeg * kDegree;
}

Pose MountCorrection::applied(const Pose& pose) const {
  return {turn(rotationRad) * pose.rotation, pose.position + cv::Vec3d(0, 0, heightM)};
}

MountAngles mountAngleChange(const Pose& before, const Pose& after) {
  const MountAngles a = mountAnglesFromRotation(before.rotation);
  const MountAngles b = mountAnglesFromRotation(after.rotation);
  return {std::remainder(b.yawDeg - a.yawDeg, 360.0), b.pitchDeg - a.pitchDeg,
          std::remainder(b.rollDeg - a.rollDeg, 360.0)};
}

Rig MountRefinementResult::corrected(const Rig& rig) const {
  Rig out = rig;
  for (std::size_t c = 0; c < out.cameras.size() && c < cameras.size(); ++c) {
    out.cameras[c].pose = cameras[c].applied(out.cameras[c].pose);
  }
  return out;
}

bool MountRefinementResult::closesSeams(std::size_t camera) const {
  for (const SeamFit& seam : seams) {
    if (!seam.touches(camera)) continue;
    if (seam.matches < MountRefinement::kMinMatches || seam.afterCm >= seam.beforeCm ||
        seam.afterCm > kClosedCm) {
      return false;
    }
  }
  return true;
}

CorrectionVerdict MountRefinementResult::verdict(std::size_t camera) const {
  const MountCorrection& correction = cameras[camera];
  if (camera == reference) return CorrectionVerdict::kHeld;
  if (!correction.conclusive()) return CorrectionVerdict::kUncertain;
  if (correction.angleDeg() > kLargestTurnDeg) return CorrectionVerdict::kTooLarge;
  if (correction.angleDeg() < kSmallestTurnDeg) return CorrectionVerdict::kTooSmall;
  if (!closesSeams(camera)) return CorrectionVerdict::kSeamsApart;
  return CorrectionVerdict::kOffered;
}

MountRefinement::MountRefinement(const Rig& rig, const PanoramaSettings& settings,
                                 std::size_t capacity)
    : rig_(rig),
      seams_(seamLines(rig, settings)),
      capacity_(std::max<std::size_t>(capacity, 1)),
      warm_(kPerCamera * rig.cameras.size(), 0.0) {
  layPatches(rig_);
}

void MountRefinement::layPatches(const Rig& through) {
  patchRig_ = through;
  patches_.clear();
  patchSeam_.clear();
  for (std::size_t s = 0; s < seams_.size(); ++s) {
    constexpr std::array kSizes{kCoarsePatches, kFinePatches};
    for (auto& patch : overlapPatches(patchRig_, seams_[s], kSizes)) {
      patches_.push_back(std::move(patch));
      patchSeam_.push_back(s);
    }
  }
}

std::optional<MountRefinementResult> MountRefinement::track(
    std::span<const cv::Mat* const> pictures, std::size_t solveEvery) {
  add(pictures);
  if (++sinceSolve_ < std::max<std::size_t>(solveEvery, 1)) return std::nullopt;
  sinceSolve_ = 0;
  auto solved = solve();
  if (!solved) return solved;
  for (std::size_t c = 0; c < solved->cameras.size(); ++c) {
    const cv::Vec3d laid = c < followed_.size() ? followed_[c].rotationRad : cv::Vec3d();
    if (cv::norm(solved->cameras[c].rotationRad - laid) / kDegree >= kFollowDeg) {
      // Patches laid through the mounts as solved line up: the next solution is finer, and
      // comes after a few sets, not a full round.
      follow(*solved);
      sinceSolve_ = solveEvery - std::min(solveEvery, kSetsAfterFollow);
      break;
    }
  }
  return solved;
}

void MountRefinement::follow(const MountRefinementResult& result) {
  followed_ = result.cameras;
  layPatches(result.corrected(rig_));
  matches_.clear();
  oldest_ = 0;
  sets_ = 0;
}

std::size_t MountRefinement::add(std::span<const cv::Mat* const> pictures) {
  std::size_t kept = 0;
  for (std::size_t p = 0; p < patches_.size(); ++p) {
    SeamMisalignmentProbe& patch = patches_[p];
    const SeamLine& seam = patch.seam();
    if (seam.left >= pictures.size() || seam.right >= pictures.size() ||
        pictures[seam.left] == nullptr || pictures[seam.right] == nullptr) {
      continue;
    }
    const SeamMisalignment measured = patch.measure(*pictures[seam.left], *pictures[seam.right]);
    // Past a quarter of the patch, too little of the two views is common to trust the peak.
    if (measured.response < kMinResponse || cv::norm(measured.shiftM) > patch.sideM() / 4) {
      continue;
    }
    // The ground the left camera shows at the patch's centre is where the right one shows it
    // shifted: two rays, fixed to the pictures (through the mounts the patch was laid with),
    // whatever the mounts turn out to be.
    const cv::Vec3d ground(patch.centre().x, patch.centre().y, 0);
    const cv::Vec3d shifted = ground + cv::Vec3d(measured.shiftM[0], measured.shiftM[1], 0);
    Match match{patchSeam_[p], cv::normalize(patchRig_.cameras[seam.left].pose.toCamera(ground)),
                cv::normalize(patchRig_.cameras[seam.right].pose.toCamera(shifted)),
                std::max(kMatchSigmaM, patch.pixelM())};
    if (matches_.size() < capacity_) {
      matches_.push_back(match);
    } else {
      matches_[oldest_] = match;
      oldest_ = (oldest_ + 1) % capacity_;
    }
    ++kept;
  }
  ++sets_;
  return kept;
}

// Per match, the distance (metres) between where its two rays meet the ground, given four
// parameters per camera; NaN where a ray misses the ground.
std::vector<double> MountRefinement::residuals(const std::vector<double>& parameters) const {
  std::vector<NudgedPose> poses;
  for (std::size_t c = 0; c < rig_.cameras.size(); ++c) {
    poses.emplace_back(rig_.cameras[c].pose, &parameters[kPerCamera * c], false);
  }
  std::vector<double> out;
  out.reserve(matches_.size());
  for (const Match& match : matches_) {
    const SeamLine& seam = seams_[match.seam];
    out.push_back(
        cv::norm(poses[seam.left].hit(match.rayLeft) - poses[seam.right].hit(match.rayRight)));
  }
  return out;
}

struct MountRefinement::Fit {
  std::vector<double> parameters;  // four per camera; the reference's stay zero
  std::vector<double> sigmas;      // likewise
  std::vector<bool> used;          // per match
  double turning = 0;              // the cameras' corrections' angles, summed
  double cost = 0;                 // robust, of the used matches and the prior
  bool solved = false;
};

MountRefinement::Fit MountRefinement::fit(std::size_t reference, std::vector<double> start,
                                          bool trim) const {
  const std::size_t cameras = rig_.cameras.size();
  // Columns of the solved parameters: every camera's four but the reference's.
  std::vector<int> column(kPerCamera * cameras, -1);
  int unknowns = 0;
  for (std::size_t c = 0; c < cameras; ++c) {
    for (std::size_t k = 0; k < kPerCamera && c != reference; ++k)
      column[kPerCamera * c + k] = unknowns++;
  }
  for (std::size_t k = 0; k < kPerCamera; ++k) start[kPerCamera * reference + k] = 0;

  Fit result;
  result.parameters = std::move(start);
  result.used.assign(matches_.size(), true);
  cv::Mat normal(unknowns, unknowns, CV_64F);
  cv::Mat gradient(unknowns, 1, CV_64F);
  const auto prior = [](std::size_t k) { return k == 3 ? kHeightPriorM : kAnglePriorRad; };

  // The robust cost the steps must lower: Huber's on each used match, and the prior.
  const auto cost = [&](const std::vector<double>& x) {
    const std::vector<double> misses = residuals(x);
    double total = 0;
    for (std::size_t m = 0; m < misses.size(); ++m) {
      if (!result.used[m]) continue;
      // In the match's own spread: coarse patches' matches count for less.
      const double u = (std::isfinite(misses[m]) ? misses[m] : 1.0) / matches_[m].sigmaM;
      total += u <= kHuber ? u * u : kHuber * (2 * u - kHuber);
    }
    for (std::size_t index = 0; index < column.size(); ++index) {
      const double p = prior(index % kPerCamera);
      if (column[index] >= 0) total += x[index] * x[index] / (p * p);
    }
    return total;
  };

  // Levenberg-Marquardt: Gauss-Newton steps on the reweighted matches, damped until they lower
  // the cost (far ground makes the problem bend).
  const auto solveOnce = [&]() {
    double damping = 1e-3;
    for (int iteration = 0; iteration < kIterations; ++iteration) {
      normal.setTo(0);
      gradient.setTo(0);
      const std::vector<double>& x = result.parameters;
      std::vector<NudgedPose> poses;
      for (std::size_t c = 0; c < cameras; ++c) {
        poses.emplace_back(rig_.cameras[c].pose, &x[kPerCamera * c], true);
      }
      for (std::size_t m = 0; m < matches_.size(); ++m) {
        if (!result.used[m]) continue;
        const Match& match = matches_[m];
        const SeamLine& seam = seams_[match.seam];
        const std::array<std::size_t, 2> sides{seam.left, seam.right};
        const std::array<const cv::Vec3d*, 2> rays{&match.rayLeft, &match.rayRight};
        const cv::Vec2d r =
            poses[seam.left].hit(match.rayLeft) - poses[seam.right].hit(match.rayRight);
        if (!std::isfinite(r[0]) || !std::isfinite(r[1])) continue;
        const double u = cv::norm(r) / match.sigmaM;
        const double weight = (u <= kHuber ? 1.0 : kHuber / u) / (match.sigmaM * match.sigmaM);
        // The residual's derivatives by the eight parameters of its two cameras.
        std::array<cv::Vec2d, 2 * kPerCamera> jacobian;
        std::array<int, 2 * kPerCamera> columns{};
        for (std::size_t side = 0; side < 2; ++side) {
          const NudgedPose& pose = poses[sides[side]];
          for (std::size_t k = 0; k < kPerCamera; ++k) {
            const cv::Vec2d change =
                pose.hit(*rays[side], 1 + 2 * k) - pose.hit(*rays[side], 2 + 2 * k);
            jacobian[kPerCamera * side + k] = change * ((side == 0 ? 1 : -1) / (2 * kStep));
            columns[kPerCamera * side + k] = column[kPerCamera * sides[side] + k];
          }
        }
        for (std::size_t i = 0; i < jacobian.size(); ++i) {
          if (columns[i] < 0) continue;
          gradient.at<double>(columns[i]) += weight * jacobian[i].dot(r);
          for (std::size_t j = 0; j < jacobian.size(); ++j) {
            if (columns[j] < 0) continue;
            normal.at<double>(columns[i], columns[j]) += weight * jacobian[i].dot(jacobian[j]);
          }
        }
      }
      for (std::size_t index = 0; index < column.size(); ++index) {
        if (column[index] < 0) continue;
        const double p = prior(index % kPerCamera);
        normal.at<double>(column[index], column[index]) += 1 / (p * p);
        gradient.at<double>(column[index]) += x[index] / (p * p);
      }
      const double was = cost(x);
      for (;;) {
        cv::Mat damped = normal.clone();
        for (int i = 0; i < unknowns; ++i) damped.at<double>(i, i) *= 1 + damping;
        cv::Mat step;
        if (!cv::solve(damped, -gradient, step, cv::DECOMP_CHOLESKY)) return false;
        std::vector<double> trial = x;
        double largest = 0;
        for (std::size_t index = 0; index < column.size(); ++index) {
          if (column[index] < 0) continue;
          trial[index] += step.at<double>(column[index]);
          largest = std::max(largest, std::abs(step.at<double>(column[index])));
        }
        if (largest < 1e-9) return true;
        if (cost(trial) <= was) {
          result.parameters = std::move(trial);
          damping = std::max(1e-6, damping / 3);
          break;
        }
        damping *= 4;
        if (damping > 1e8) return true;
      }
    }
    return true;
  };

  if (!solveOnce()) return result;
  if (trim) {
    // Left out: matches past four times the residuals' robust spread (and past 2 cm).
    const std::vector<double> misses = residuals(result.parameters);
    std::vector<double> finite;
    for (const double miss : misses) {
      if (std::isfinite(miss)) finite.push_back(miss);
    }
    const double limit = std::max(0.02, 4 * 1.4826 * median(finite));
    for (std::size_t m = 0; m < misses.size(); ++m) {
      result.used[m] = std::isfinite(misses[m]) && misses[m] <= limit;
    }
    if (!solveOnce()) return result;
  }
  result.cost = cost(result.parameters);

  // The spread: the residuals' own (their variance against the assumed one), times the
  // fit's inverse normal matrix.
  const std::vector<double> misses = residuals(result.parameters);
  double squares = 0;
  std::size_t count = 0;
  for (std::size_t m = 0; m < misses.size(); ++m) {
    if (!result.used[m] || !std::isfinite(misses[m])) continue;
    squares += misses[m] * misses[m] / (matches_[m].sigmaM * matches_[m].sigmaM);
    ++count;
  }
  const double dof = std::max(1.0, 2.0 * static_cast<double>(count) - unknowns);
  const double variance = std::max(1.0, squares / dof);
  cv::Mat covariance;
  cv::invert(normal, covariance, cv::DECOMP_CHOLESKY);
  result.sigmas.assign(column.size(), 0.0);
  for (std::size_t index = 0; index < column.size(); ++index) {
    if (column[index] < 0) continue;
    result.sigmas[index] =
        std::sqrt(variance * covariance.at<double>(column[index], column[index]));
  }
  for (std::size_t c = 0; c < cameras; ++c) {
    const double* p = &result.parameters[kPerCamera * c];
    result.turning += std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
  }
  result.solved = true;
  return result;
}

std::optional<MountRefinementResult> MountRefinement::solve() {
  const std::size_t cameras = rig_.cameras.size();
  std::vector<std::size_t> perCamera(cameras, 0);
  for (const Match& match : matches_) {
    ++perCamera[seams_[match.seam].left];
    ++perCamera[seams_[match.seam].right];
  }
  if (cameras < 2 ||
      std::ranges::any_of(perCamera, [](std::size_t n) { return n < kMinMatches; })) {
    return std::nullopt;
  }

  // Each camera held in turn, warm-started from the last fit. Holding a knocked camera leaves
  // the seams apart (a cost several times the others'); of the fits that bring them together
  // alike, the one that turns the cameras least wins.
  std::vector<Fit> fits;
  for (std::size_t held = 0; held < cameras; ++held) fits.push_back(fit(held, warm_, true));
  double lowest = std::numeric_limits<double>::infinity();
  for (const Fit& candidate : fits) {
    if (candidate.solved) lowest = std::min(lowest, candidate.cost);
  }
  std::optional<Fit> best;
  std::size_t reference = 0;
  for (std::size_t held = 0; held < cameras; ++held) {
    Fit& candidate = fits[held];
    if (!candidate.solved || candidate.cost > kAlikeCost * lowest) continue;
    if (!best || candidate.turning < best->turning) {
      best = std::move(candidate);
      reference = held;
    }
  }
  if (!best) return std::nullopt;
  warm_ = best->parameters;

  MountRefinementResult result;
  result.reference = reference;
  result.sets = sets_;
  for (std::size_t c = 0; c < cameras; ++c) {
    const double* p = &best->parameters[kPerCamera * c];
    const double* s = &best->sigmas[kPerCamera * c];
    result.cameras.push_back({{p[0], p[1], p[2]}, p[3], {s[0], s[1], s[2]}, s[3]});
  }
  const std::vector<double> before = residuals(std::vector<double>(warm_.size(), 0.0));
  const std::vector<double> after = residuals(best->parameters);
  for (std::size_t s = 0; s < seams_.size(); ++s) {
    // Told by the fine patches' matches where there are any: the coarse ones are a few
    // centimetres off by themselves.
    std::vector<double> was;
    std::vector<double> is;
    for (const bool coarseToo : {false, true}) {
      for (std::size_t m = 0; m < matches_.size(); ++m) {
        const bool fine = matches_[m].sigmaM < kCoarsePatches.finestM;
        if (matches_[m].seam != s || !best->used[m] || (!fine && !coarseToo)) continue;
        was.push_back(before[m]);
        is.push_back(after[m]);
      }
      if (!is.empty()) break;
    }
    result.seams.push_back({seams_[s].name, seams_[s].left, seams_[s].right, is.size(),
                            100 * median(was), 100 * median(is)});
  }
  result.matches = static_cast<std::size_t>(std::ranges::count(best->used, true));
  result.rejected = matches_.size() - result.matches;
  return result;
}

}  // namespace surroundd::processing
