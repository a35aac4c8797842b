#include "tools/bench/seam_measures.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <opencv2/imgproc.hpp>

namespace surroundd::bench {
namespace {

constexpr double kDegree = std::numbers::pi / 180;
constexpr double kStripRad = 1.5 * kDegree;

constexpr std::array<double, 2> kNear{-15, -35};  // elevation ranges, degrees
constexpr std::array<double, 2> kFar{-2, -12};
constexpr std::size_t kMinimumSamples = 20;
// The view step's bands: 1 degree, or this many rows; a band counts with this many pixels that
// both cameras see.
constexpr double kBandRows = 4;
constexpr std::size_t kMinimumViewSamples = 12;
// A correction's gain is read where neither the raw nor the corrected level is near black or
// clipped.
constexpr std::array<int, 2> kRatioLevels{16, 200};

using ChannelSamples = std::array<std::vector<float>, 3>;

double meanAbsolute(const cv::Vec3d& difference) {
  return (std::abs(difference[0]) + std::abs(difference[1]) + std::abs(difference[2])) / 3;
}

double median(std::vector<float>& values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

cv::Vec3d bilinearAt(const cv::Mat& image, const cv::Point2d& p) {
  const int x = static_cast<int>(std::floor(p.x));
  const int y = static_cast<int>(std::floor(p.y));
  const double fx = p.x - x;
  const double fy = p.y - y;
  const auto at = [&](int dx, int dy) {
    return cv::Vec3d(image.at<cv::Vec3b>(std::clamp(y + dy, 0, image.rows - 1),
                                         std::clamp(x + dx, 0, image.cols - 1)));
  };
  return (at(0, 0) * (1 - fx) + at(1, 0) * fx) * (1 - fy) +
         (at(0, 1) * (1 - fx) + at(1, 1) * fx) * fy;
}

// The 1.5 degree strips just past the blend band on each side of a seam, as panorama columns
// [first, last) (to be wrapped) and rows [v0, v1) between two elevations.
struct SeamStrips {
  std::array<int, 2> left{}, right{};
  int v0 = 0, v1 = 0;
};

SeamStrips seamStrips(const processing::PanoramaSettings& settings, const SeamLine& seam,
                      double topDeg, double bottomDeg) {
  const auto& g = settings.geometry;
  const int width = static_cast<int>(kStripRad * g.size.width / (2 * std::numbers::pi));
  const auto column = [&](double azimuth) {
    return static_cast<int>(std::lround(g.column(azimuth)));
  };
  const int leftFirst = column(seam.azimuthRad + settings.featherRad / 2);
  const int rightLast = column(seam.azimuthRad - settings.featherRad / 2);
  return {{leftFirst, leftFirst + width},
          {rightLast - width, rightLast},
          static_cast<int>(std::lround(g.row(topDeg * kDegree))),
          static_cast<int>(std::lround(g.row(bottomDeg * kDegree)))};
}

// Calls visit(u, v) for each seen pixel of columns [first, last) (wrapped) and rows [v0, v1).
template <typename Visit>
void forStripPixels(const processing::PanoramaLut& lut, const std::array<int, 2>& columns, int v0,
                    int v1, Visit&& visit) {
  for (int v = std::max(v0, 0); v < std::min(v1, lut.size.height); ++v) {
    for (int k = columns[0]; k < columns[1]; ++k) {
      const int u = (k % lut.size.width + lut.size.width) % lut.size.width;
      if (lut.taps[static_cast<std::size_t>(v) * lut.size.width + u].camera !=
          processing::PanoramaLut::kUnseen) {
        visit(u, v);
      }
    }
  }
}

// True where panorama pixel (u, v) is camera `camera`'s alone, blended with no other.
bool ownPixel(const processing::PanoramaLut& lut, int u, int v, std::size_t camera) {
  const std::uint32_t pixel = static_cast<std::uint32_t>(v) * lut.size.width + u;
  if (lut.taps[pixel].camera != camera) return false;
  const auto first = lut.blendTaps.begin() + lut.blendRowBegin[static_cast<std::size_t>(v)];
  const auto last = lut.blendTaps.begin() + lut.blendRowBegin[static_cast<std::size_t>(v) + 1];
  return !std::binary_search(first, last, processing::BlendTap{pixel, {}},
                             [](const auto& a, const auto& b) { return a.pixel < b.pixel; });
}

// Per-channel median of the seen pixels of `panorama` in columns [u0, u1) (wrapped) and rows
// [v0, v1); nullopt with fewer than 20 of them.
std::optional<cv::Vec3d> stripMedian(const cv::Mat& panorama, const processing::PanoramaLut& lut,
                                     int u0, int u1, int v0, int v1) {
  ChannelSamples values;
  forStripPixels(lut, {u0, u1}, v0, v1, [&](int u, int v) {
    const auto& pixel = panorama.at<cv::Vec3b>(v, u);
    for (int c = 0; c < 3; ++c) values[static_cast<std::size_t>(c)].push_back(pixel[c]);
  });
  if (values[0].size() < kMinimumSamples) return std::nullopt;
  return cv::Vec3d(median(values[0]), median(values[1]), median(values[2]));
}

}  // namespace

SeamColourStep seamColourStep(const cv::Mat& panorama, const processing::PanoramaLut& lut,
                              const processing::PanoramaSettings& settings, const SeamLine& seam) {
  const auto step = [&](double topDeg, double bottomDeg) -> std::optional<double> {
    const SeamStrips strips = seamStrips(settings, seam, topDeg, bottomDeg);
    const auto left =
        stripMedian(panorama, lut, strips.left[0], strips.left[1], strips.v0, strips.v1);
    const auto right =
        stripMedian(panorama, lut, strips.right[0], strips.right[1], strips.v0, strips.v1);
    if (!left || !right) return std::nullopt;
    return meanAbsolute(*left - *right);
  };
  return {step(kNear[0], kNear[1]), step(kFar[0], kFar[1])};
}

SeamColourStep seamViewStep(const cv::Mat& raw, const cv::Mat& corrected,
                            const processing::PanoramaProjector& projector,
                            const processing::PanoramaLut& lut, std::span<const cv::Mat> frames,
                            const SeamLine& seam) {
  const auto& settings = projector.settings();
  const std::array<std::size_t, 2> cameras{seam.left, seam.right};
  struct Band {
    std::array<ChannelSamples, 2> ratios, views;
  };
  const auto step = [&](double topDeg, double bottomDeg) -> std::optional<double> {
    // Bands of 1 degree, or of kBandRows where the panorama is too small for that.
    const double rowsPerDegree = settings.geometry.size.height / 180.0;
    const double bandDeg = std::max(1.0, kBandRows / rowsPerDegree);
    std::vector<Band> bands;
    Band whole;  // its ratios: where a band has none of a camera's own pixels
    const int count = static_cast<int>(std::ceil((topDeg - bottomDeg) / bandDeg));
    for (int k = 0; k < count; ++k) {
      const double top = topDeg - k * bandDeg;
      const SeamStrips strips = seamStrips(settings, seam, top, std::max(top - bandDeg, bottomDeg));
      Band& band = bands.emplace_back();
      // Each camera's correction: the ratios corrected / raw of its own pixels in its strip.
      for (std::size_t side = 0; side < 2; ++side) {
        forStripPixels(lut, side == 0 ? strips.left : strips.right, strips.v0, strips.v1,
                       [&](int u, int v) {
                         if (!ownPixel(lut, u, v, cameras[side])) return;
                         const auto& before = raw.at<cv::Vec3b>(v, u);
                         const auto& after = corrected.at<cv::Vec3b>(v, u);
                         for (int c = 0; c < 3; ++c) {
                           if (before[c] < kRatioLevels[0] || before[c] > kRatioLevels[1]) continue;
                           const float ratio = static_cast<float>(after[c]) / before[c];
                           band.ratios[side][static_cast<std::size_t>(c)].push_back(ratio);
                           whole.ratios[side][static_cast<std::size_t>(c)].push_back(ratio);
                         }
                       });
      }
      // Both cameras' views of every pixel from one strip to the other that both see.
      forStripPixels(lut, {strips.right[0], strips.left[1]}, strips.v0, strips.v1,
                     [&](int u, int v) {
                       const auto left = projector.cameraPixel(seam.left, cv::Point2d(u, v));
                       const auto right = projector.cameraPixel(seam.right, cv::Point2d(u, v));
                       if (!left || !right) return;
                       const std::array<cv::Vec3d, 2> seen{bilinearAt(frames[seam.left], *left),
                                                           bilinearAt(frames[seam.right], *right)};
                       for (std::size_t side = 0; side < 2; ++side) {
                         for (int c = 0; c < 3; ++c) {
                           band.views[side][static_cast<std::size_t>(c)].push_back(
                               static_cast<float>(seen[side][c]));
                         }
                       }
                     });
    }
    std::array<cv::Vec3d, 2> wholeGain;
    for (std::size_t side = 0; side < 2; ++side) {
      for (std::size_t c = 0; c < 3; ++c) {
        if (whole.ratios[side][c].empty()) return std::nullopt;  // a correction not seen
        wholeGain[side][static_cast<int>(c)] = median(whole.ratios[side][c]);
      }
    }
    double sum = 0;
    int measured = 0;
    for (Band& band : bands) {
      if (band.views[0][0].size() < kMinimumViewSamples) continue;
      std::array<cv::Vec3d, 2> medians;
      for (std::size_t side = 0; side < 2; ++side) {
        for (std::size_t c = 0; c < 3; ++c) {
          auto& ratios = band.ratios[side][c];
          const double gain =
              ratios.empty() ? wholeGain[side][static_cast<int>(c)] : median(ratios);
          for (float& level : band.views[side][c]) {
            level = static_cast<float>(std::min(255.0, level * gain));
          }
          medians[side][static_cast<int>(c)] = median(band.views[side][c]);
        }
      }
      sum += meanAbsolute(medians[0] - medians[1]);
      ++measured;
    }
    return measured == 0 ? std::nullopt : std::optional<double>(sum / measured);
  };
  return {step(kNear[0], kNear[1]), step(kFar[0], kFar[1])};
}

double meanLevel(const cv::Mat& panorama, const processing::PanoramaLut& lut) {
  const cv::Scalar mean = cv::mean(panorama, lut.validMask());
  return (mean[0] + mean[1] + mean[2]) / 3;
}

double chromaSpread(const cv::Mat& panorama, const processing::PanoramaLut& lut,
                    const processing::PanoramaSettings& settings) {
  cv::Mat lab;
  cv::cvtColor(panorama, lab, cv::COLOR_BGR2Lab, 3);
  lab.convertTo(lab, CV_32FC3);  // 8-bit L*a*b*: a* and b* centred on 128, one unit a level
  cv::Mat owner = lut.ownerMap();
  const int horizon =
      std::clamp(static_cast<int>(std::ceil(settings.geometry.row(0))), 0, owner.rows);
  owner.rowRange(0, horizon).setTo(processing::PanoramaLut::kUnseen);
  std::vector<cv::Vec2d> means;
  for (std::size_t c = 0; c < lut.cameraSizes.size(); ++c) {
    const cv::Mat owned = owner == static_cast<int>(c);
    if (cv::countNonZero(owned) == 0) continue;
    const cv::Scalar mean = cv::mean(lab, owned);
    means.emplace_back(mean[1], mean[2]);
  }
  if (means.empty()) return 0;
  cv::Vec2d average(0, 0);
  for (const auto& m : means) average += m / static_cast<double>(means.size());
  double variance = 0;
  for (const auto& m : means) {
    const cv::Vec2d d = m - average;
    variance += d.dot(d) / static_cast<double>(means.size());
  }
  return std::sqrt(variance);
}

}  // namespace surroundd::bench
