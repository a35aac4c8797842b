#include "processing/calibration/overlap_patches.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "processing/calibration/ground_top_view.hpp"
#include "processing/lens/camera_model.hpp"

namespace surroundd::processing {
namespace {

constexpr double kCellM = 0.1;
constexpr double kReachM = 15;
constexpr double kFarthestM = 12;
constexpr int kMaxPatches = 24;
constexpr int kPatchSides[] = {64, 96, 128};

// How many metres of ground one pixel of `camera` spans at `ground`, along the direction it spans
// most; infinite where the camera does not see it.
double groundPerPixel(const CameraModel& model, const Pose& pose, const cv::Vec3d& ground) {
  const auto at = model.project(pose.toCamera(ground));
  if (!at) return std::numeric_limits<double>::infinity();
  double coarsest = 0;
  for (const cv::Vec3d& step : {cv::Vec3d(0.01, 0, 0), cv::Vec3d(0, 0.01, 0)}) {
    const auto next = model.project(pose.toCamera(ground + step));
    if (!next) return std::numeric_limits<double>::infinity();
    coarsest = std::max(coarsest, 0.01 / std::max(1e-9, cv::norm(*next - *at)));
  }
  return coarsest;
}

// The ground both cameras of `seam` see, on a kCellM grid (GroundGrid's layout), 255 where seen.
cv::Mat overlapMask(const Rig& rig, const SeamLine& seam, const GroundGrid& grid) {
  cv::Mat both(grid.size, CV_8U, cv::Scalar(255));
  for (const std::size_t c : {seam.left, seam.right}) {
    const CameraCalibration& camera = rig.cameras[c];
    const GroundSampling sampling = groundSampling(camera, grid);
    both &= sampling.mapX >= 0;
    for (int row = 0; row < grid.size.height; ++row) {
      for (int column = 0; column < grid.size.width; ++column) {
        const cv::Vec3d ground = grid.groundAt(row, column);
        const cv::Vec3d away = ground - camera.pose.position;
        if (std::hypot(away[0], away[1]) > kFarthestM) both.at<std::uint8_t>(row, column) = 0;
      }
    }
  }
  return both;
}

}  // namespace

std::vector<SeamMisalignmentProbe> overlapPatches(const Rig& rig, const SeamLine& seam,
                                                  std::span<const PatchSizes> sizeRanges) {
  const int cells = static_cast<int>(2 * kReachM / kCellM);
  const GroundGrid grid{{0, 0}, kCellM, {cells, cells}};
  const cv::Mat both = overlapMask(rig, seam, grid);
  cv::Mat room;  // per cell, how far (in cells) to the nearest ground the two do not both see
  cv::distanceTransform(both, room, cv::DIST_C, 3);
  const std::array<CameraModel, 2> models{CameraModel(rig.cameras[seam.left].intrinsics),
                                          CameraModel(rig.cameras[seam.right].intrinsics)};
  std::vector<SeamMisalignmentProbe> patches;
  for (const PatchSizes& sizes : sizeRanges) {
    struct Candidate {
      cv::Vec3d ground;
      double sideM = 0;
      double nearness = 0;  // the distances to the two cameras, summed, per metre of patch
    };
    std::vector<Candidate> candidates;
    for (int row = 0; row < cells; ++row) {
      for (int column = 0; column < cells; ++column) {
        const double sideM = std::min(sizes.largestM, 2 * room.at<float>(row, column) * kCellM);
        if (sideM < sizes.smallestM) continue;
        const cv::Vec3d ground = grid.groundAt(row, column);
        double nearness = 0;
        for (const std::size_t c : {seam.left, seam.right}) {
          nearness += cv::norm(ground - rig.cameras[c].pose.position);
        }
        candidates.push_back({ground, sideM, nearness / sideM});
      }
    }
    std::ranges::sort(candidates, {}, &Candidate::nearness);
    std::vector<Candidate> placed;
    for (const Candidate& candidate : candidates) {
      if (std::cmp_greater_equal(placed.size(), kMaxPatches)) break;
      const bool crowded = std::ranges::any_of(placed, [&](const Candidate& other) {
        return cv::norm(candidate.ground - other.ground) < (candidate.sideM + other.sideM) / 4;
      });
      if (crowded) continue;
      // Sampled as finely as the coarser camera sees that ground, no finer than 1 cm.
      const double perPixel = std::max(
          {sizes.finestM, groundPerPixel(models[0], rig.cameras[seam.left].pose, candidate.ground),
           groundPerPixel(models[1], rig.cameras[seam.right].pose, candidate.ground)});
      int side = kPatchSides[0];  // finer than the cameras where the overlap is narrow
      for (const int allowed : kPatchSides) {
        if (allowed * perPixel <= candidate.sideM) side = allowed;
      }
      auto patch = SeamMisalignmentProbe::at(rig, seam, {candidate.ground[0], candidate.ground[1]},
                                             side, candidate.sideM / side);
      if (!patch) continue;
      patches.push_back(std::move(*patch));
      placed.push_back(candidate);
    }
  }
  return patches;
}

}  // namespace surroundd::processing
