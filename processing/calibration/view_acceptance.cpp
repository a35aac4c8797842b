#include "processing/calibration/view_acceptance.hpp"

#include <algorithm>
#include <map>
#include <utility>

#include <opencv2/imgproc.hpp>

namespace surroundd::processing {
namespace {

constexpr float kProfileStepPx = 0.25f;

// The intensity profile across the edge from corner a to corner b, through its middle, over 70 %
// of the square on either side (clear of the neighbouring corners' edges).
std::vector<float> profileAcross(const cv::Mat& gray, cv::Point2f a, cv::Point2f b) {
  const cv::Point2f middle = (a + b) * 0.5f;
  const float length = static_cast<float>(cv::norm(b - a));
  const cv::Point2f normal = cv::Point2f(a.y - b.y, b.x - a.x) * (1.0f / length);
  const int half = static_cast<int>(0.35f * length / kProfileStepPx);
  cv::Mat mapX(1, 2 * half + 1, CV_32F), mapY(1, 2 * half + 1, CV_32F);
  for (int i = -half; i <= half; ++i) {
    const cv::Point2f p = middle + normal * (static_cast<float>(i) * kProfileStepPx);
    mapX.at<float>(i + half) = p.x;
    mapY.at<float>(i + half) = p.y;
  }
  cv::Mat profile;
  cv::remap(gray, profile, mapX, mapY, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  std::vector<float> values;
  profile.convertTo(values, CV_32F);
  return values;
}

double hullOverlap(const std::vector<cv::Point2f>& a, const std::vector<cv::Point2f>& b) {
  std::vector<cv::Point2f> hullA, hullB, common;
  cv::convexHull(a, hullA);
  cv::convexHull(b, hullB);
  const double intersection = cv::intersectConvexConvex(hullA, hullB, common);
  const double united = cv::contourArea(hullA) + cv::contourArea(hullB) - intersection;
  return united > 0 ? intersection / united : 0;
}

// Each pair of corners next to each other on the board's grid (a square's side).
std::vector<std::pair<cv::Point2f, cv::Point2f>> neighbourPairs(const BoardView& view) {
  std::map<std::pair<int, int>, cv::Point2f> byGrid;
  for (std::size_t i = 0; i < view.grid.size(); ++i) {
    byGrid[{view.grid[i].x, view.grid[i].y}] = view.corners[i];
  }
  std::vector<std::pair<cv::Point2f, cv::Point2f>> pairs;
  for (const auto& [at, corner] : byGrid) {
    for (const auto& next : {std::pair{at.first + 1, at.second}, {at.first, at.second + 1}}) {
      if (const auto neighbour = byGrid.find(next); neighbour != byGrid.end()) {
        pairs.emplace_back(corner, neighbour->second);
      }
    }
  }
  return pairs;
}

}  // namespace

double edgeWidthPx(const cv::Mat& gray, const BoardView& view) {
  std::vector<double> widths;
  for (const auto& [corner, next] : neighbourPairs(view)) {
    if (cv::norm(next - corner) < 6) continue;
    const auto profile = profileAcross(gray, corner, next);
    float steepest = 0;
    for (std::size_t i = 1; i < profile.size(); ++i) {
      steepest = std::max(steepest, std::abs(profile[i] - profile[i - 1]) / kProfileStepPx);
    }
    const auto [darkest, brightest] = std::minmax_element(profile.begin(), profile.end());
    if (steepest > 0) widths.push_back((*brightest - *darkest) / steepest);
  }
  return median(widths);
}

double squareSizePx(const BoardView& view) {
  std::vector<double> sides;
  for (const auto& [corner, next] : neighbourPairs(view)) sides.push_back(cv::norm(next - corner));
  return median(sides);
}

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

std::vector<DuplicateView> findDuplicateViews(std::span<const BoardView> views, double minOverlap) {
  std::vector<DuplicateView> duplicates;
  for (std::size_t v = 1; v < views.size(); ++v) {
    for (std::size_t earlier = 0; earlier < v; ++earlier) {
      const bool alreadyARepeat =
          std::any_of(duplicates.begin(), duplicates.end(),
                      [&](const DuplicateView& d) { return d.view == earlier; });
      if (alreadyARepeat) continue;
      const double overlap = hullOverlap(views[v].corners, views[earlier].corners);
      if (overlap >= minOverlap) {
        duplicates.push_back({v, earlier, overlap});
        break;
      }
    }
  }
  return duplicates;
}

}  // namespace surroundd::processing
