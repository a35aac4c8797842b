#include "processing/calibration/seam_misalignment.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include <opencv2/imgproc.hpp>

#include "processing/calibration/ground_top_view.hpp"

namespace surroundd::processing {
namespace {

constexpr double kDegree = std::numbers::pi / 180;
constexpr double kPatchM = 1.6;
constexpr double kPatchPixelM = 0.01;
constexpr double kMinimumSeen = 0.8;

double wrap(double angle) { return std::remainder(angle, 2 * std::numbers::pi); }

}  // namespace

std::vector<SeamLine> seamLines(const Rig& rig, const PanoramaSettings& settings) {
  const PanoramaProjector projector(rig, settings);
  std::vector<std::size_t> order(rig.cameras.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::ranges::sort(order, {}, [&](std::size_t c) { return projector.axisAzimuth(c); });
  std::vector<SeamLine> seams;
  for (std::size_t k = 0; k < order.size() && order.size() > 1; ++k) {
    const std::size_t right = order[k];
    const std::size_t left = order[(k + 1) % order.size()];
    const double a = projector.axisAzimuth(right);
    double gap = std::fmod(projector.axisAzimuth(left) - a, 2 * std::numbers::pi);
    if (gap <= 0) gap += 2 * std::numbers::pi;
    seams.push_back(
        {left, right, wrap(a + gap / 2), rig.cameras[left].name + "/" + rig.cameras[right].name});
  }
  return seams;
}

std::optional<SeamMisalignmentProbe> SeamMisalignmentProbe::make(const Rig& rig,
                                                                 const PanoramaSettings& settings,
                                                                 const SeamLine& seam) {
  // The nearest ground under the seam that both cameras see past the vehicle's body.
  for (const double elevationDeg : {25.0, 18.0, 12.0, 8.0, 5.0}) {
    const double distance = settings.geometry.centre[2] / std::tan(elevationDeg * kDegree);
    const cv::Point2d centre(distance * std::cos(seam.azimuthRad),
                             distance * std::sin(seam.azimuthRad));
    if (auto probe =
            at(rig, seam, centre, static_cast<int>(kPatchM / kPatchPixelM), kPatchPixelM)) {
      return probe;
    }
  }
  return std::nullopt;
}

std::optional<SeamMisalignmentProbe> SeamMisalignmentProbe::at(const Rig& rig, const SeamLine& seam,
                                                               const cv::Point2d& centre, int side,
                                                               double pixelM) {
  SeamMisalignmentProbe probe;
  for (std::size_t k = 0; k < 2; ++k) {
    // Patch rows run along -x of the vehicle, columns along -y: a top view, front up.
    auto sampling = groundSampling(rig.cameras[k == 0 ? seam.left : seam.right],
                                   {centre, pixelM, {side, side}});
    if (sampling.seen < kMinimumSeen * side * side) return std::nullopt;
    probe.seen_[k] = sampling.mapX >= 0;
    probe.unseen_[k] = sampling.mapX < 0;
    probe.mapX_[k] = std::move(sampling.mapX);
    probe.mapY_[k] = std::move(sampling.mapY);
  }
  probe.seam_ = seam;
  probe.distanceM_ = std::hypot(centre.x, centre.y);
  probe.centre_ = centre;
  probe.pixelM_ = pixelM;
  cv::createHanningWindow(probe.window_, {side, side}, CV_32F);
  return probe;
}

SeamMisalignment SeamMisalignmentProbe::measure(const cv::Mat& left, const cv::Mat& right) {
  for (std::size_t k = 0; k < 2; ++k) {
    // The patch alone is resampled and turned grey: a fraction of the picture.
    cv::remap(k == 0 ? left : right, colour_[k], mapX_[k], mapY_[k], cv::INTER_LINEAR,
              cv::BORDER_CONSTANT, cv::Scalar::all(0));
    cv::cvtColor(colour_[k], grey_[k], cv::COLOR_BGR2GRAY);
    grey_[k].convertTo(patch_[k], CV_32F);
    // Around its mean, and at it where the camera does not see: the window would otherwise
    // make two plain patches alike at no shift, and a patch's edge would be a feature.
    patch_[k] -= cv::mean(patch_[k], seen_[k]);
    patch_[k].setTo(0, unseen_[k]);
  }
  SeamMisalignment result;
  result.distanceM = distanceM_;
  const cv::Point2d shift = cv::phaseCorrelate(patch_[0], patch_[1], window_, &result.response);
  result.shiftCm = std::hypot(shift.x, shift.y) * pixelM_ * 100;
  // Columns run along -y, rows along -x (GroundGrid).
  result.shiftM = {-shift.y * pixelM_, -shift.x * pixelM_};
  return result;
}

std::optional<SeamMisalignment> seamMisalignment(const Rig& rig, std::span<const cv::Mat> frames,
                                                 const PanoramaSettings& settings,
                                                 const SeamLine& seam) {
  auto probe = SeamMisalignmentProbe::make(rig, settings, seam);
  if (!probe) return std::nullopt;
  return probe->measure(frames[seam.left], frames[seam.right]);
}

}  // namespace surroundd::processing
