#include "tools/bench/seam_measures.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <numeric>

#include <opencv2/imgproc.hpp>

namespace surroundd::bench {
namespace {

constexpr double kDegree = std::numbers::pi / 180;
constexpr double kStripRad = 1.5 * kDegree;
constexpr double kPatchM = 1.6;
constexpr double kPatchPixelM = 0.01;
constexpr double kMinimumSeen = 0.8;

double wrap(double angle) { return std::remainder(angle, 2 * std::numbers::pi); }

// Per-channel median of the seen pixels of `panorama` in columns [u0, u1) (wrapped) and rows
// [v0, v1); nullopt with fewer than 20 of them.
std::optional<cv::Vec3d> stripMedian(const cv::Mat& panorama, const processing::PanoramaLut& lut,
                                     int u0, int u1, int v0, int v1) {
  std::array<std::vector<std::uint8_t>, 3> values;
  for (int v = std::max(v0, 0); v < std::min(v1, panorama.rows); ++v) {
    for (int k = u0; k < u1; ++k) {
      const int u = (k % panorama.cols + panorama.cols) % panorama.cols;
      if (lut.taps[static_cast<std::size_t>(v) * lut.size.width + u].camera ==
          processing::PanoramaLut::kUnseen) {
        continue;
      }
      const auto& pixel = panorama.at<cv::Vec3b>(v, u);
      for (int c = 0; c < 3; ++c) values[static_cast<std::size_t>(c)].push_back(pixel[c]);
    }
  }
  if (values[0].size() < 20) return std::nullopt;
  cv::Vec3d median;
  for (int c = 0; c < 3; ++c) {
    auto& channel = values[static_cast<std::size_t>(c)];
    std::nth_element(channel.begin(),
                     channel.begin() + static_cast<std::ptrdiff_t>(channel.size() / 2),
                     channel.end());
    median[c] = channel[channel.size() / 2];
  }
  return median;
}

std::optional<SeamAlignment> alignmentAt(const processing::Rig& rig,
                                         std::span<const cv::Mat> frames, const SeamLine& seam,
                                         double distance) {
  const cv::Point2d centre(distance * std::cos(seam.azimuthRad),
                           distance * std::sin(seam.azimuthRad));
  const int side = static_cast<int>(kPatchM / kPatchPixelM);
  std::array<cv::Mat, 2> patches;
  for (int k = 0; k < 2; ++k) {
    const std::size_t camera = k == 0 ? seam.left : seam.right;
    const auto& calibration = rig.cameras[camera];
    const processing::CameraModel model(calibration.intrinsics);
    cv::Mat mapX(side, side, CV_32F, cv::Scalar(-1));
    cv::Mat mapY(side, side, CV_32F, cv::Scalar(-1));
    int seen = 0;
    for (int y = 0; y < side; ++y) {
      for (int x = 0; x < side; ++x) {
        // Patch rows run along -x of the vehicle, columns along -y: a top view, front up.
        const cv::Vec3d ground(centre.x + (side / 2.0 - y) * kPatchPixelM,
                               centre.y + (side / 2.0 - x) * kPatchPixelM, 0);
        const auto pixel = model.project(calibration.pose.toCamera(ground));
        if (!pixel || !model.inImage(*pixel)) continue;
        const cv::Mat& body = calibration.bodyMask;
        if (!body.empty() && body.at<std::uint8_t>(static_cast<int>(std::lround(pixel->y)),
                                                   static_cast<int>(std::lround(pixel->x))) != 0) {
          continue;
        }
        mapX.at<float>(y, x) = static_cast<float>(pixel->x);
        mapY.at<float>(y, x) = static_cast<float>(pixel->y);
        ++seen;
      }
    }
    if (seen < kMinimumSeen * side * side) return std::nullopt;
    cv::Mat grey;
    cv::cvtColor(frames[camera], grey, cv::COLOR_BGR2GRAY);
    cv::Mat patch;
    cv::remap(grey, patch, mapX, mapY, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
    patch.convertTo(patches[static_cast<std::size_t>(k)], CV_32F);
  }
  cv::Mat window;
  cv::createHanningWindow(window, patches[0].size(), CV_32F);
  SeamAlignment alignment;
  alignment.distanceM = distance;
  const cv::Point2d shift = cv::phaseCorrelate(patches[0], patches[1], window, &alignment.response);
  alignment.shiftCm = std::hypot(shift.x, shift.y) * kPatchPixelM * 100;
  return alignment;
}

}  // namespace

std::vector<SeamLine> seamLines(const processing::Rig& rig,
                                const processing::PanoramaSettings& settings) {
  const processing::PanoramaProjector projector(rig, settings);
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

SeamColourStep seamColourStep(const cv::Mat& panorama, const processing::PanoramaLut& lut,
                              const processing::PanoramaSettings& settings, const SeamLine& seam) {
  const auto& g = settings.geometry;
  const double pixelsPerRad = g.size.width / (2 * std::numbers::pi);
  const auto column = [&](double azimuth) {
    return static_cast<int>(std::lround(g.column(azimuth)));
  };
  const auto row = [&](double elevation) {
    return static_cast<int>(std::lround(g.row(elevation)));
  };
  const double half = settings.featherRad / 2;
  const auto step = [&](double topDeg, double bottomDeg) -> std::optional<double> {
    const int v0 = row(topDeg * kDegree);
    const int v1 = row(bottomDeg * kDegree);
    const int leftFirst = column(seam.azimuthRad + half);
    const int rightLast = column(seam.azimuthRad - half);
    const auto left = stripMedian(panorama, lut, leftFirst,
                                  leftFirst + static_cast<int>(kStripRad * pixelsPerRad), v0, v1);
    const auto right = stripMedian(
        panorama, lut, rightLast - static_cast<int>(kStripRad * pixelsPerRad), rightLast, v0, v1);
    if (!left || !right) return std::nullopt;
    const cv::Vec3d difference = *left - *right;
    return (std::abs(difference[0]) + std::abs(difference[1]) + std::abs(difference[2])) / 3;
  };
  return {step(-15, -35), step(-2, -12)};
}

std::optional<SeamAlignment> seamAlignment(const processing::Rig& rig,
                                           std::span<const cv::Mat> frames,
                                           const processing::PanoramaSettings& settings,
                                           const SeamLine& seam) {
  // The nearest ground under the seam that both cameras see past the vehicle's body: at
  // elevations -25, -18, -12, -8 and -5 degrees from the panorama's centre.
  for (const double elevationDeg : {25.0, 18.0, 12.0, 8.0, 5.0}) {
    const double distance = settings.geometry.centre[2] / std::tan(elevationDeg * kDegree);
    if (auto alignment = alignmentAt(rig, frames, seam, distance)) return alignment;
  }
  return std::nullopt;
}

double meanLevel(const cv::Mat& panorama, const processing::PanoramaLut& lut) {
  const cv::Scalar mean = cv::mean(panorama, lut.validMask());
  return (mean[0] + mean[1] + mean[2]) / 3;
}

}  // namespace surroundd::bench
