#include "processing/calibration/ground_marker_detection.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <tuple>

#include <fmt/format.h>

#include "processing/calibration/target_detection.hpp"

namespace surroundd::processing {
namespace {

cv::Point2f centroid(const std::vector<cv::Point2f>& points) {
  cv::Point2f sum(0, 0);
  for (const auto& p : points) sum += p;
  return sum * (1.0f / static_cast<float>(points.size()));
}

// Boards of one pattern: the closest (found board, predicted board) pairs first, each used once.
void matchBoards(std::vector<std::vector<cv::Point2f>> found,
                 const std::vector<std::size_t>& candidates, const MarkerLayout& layout,
                 const CameraModel& model, const Pose& prior,
                 std::vector<MarkerSighting>& sightings) {
  std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;  // distance, found, candidate
  for (std::size_t f = 0; f < found.size(); ++f) {
    const cv::Point2f centre = centroid(found[f]);
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      const auto predicted = model.project(prior.toCamera(layout.markers[candidates[c]].centre));
      // With one board of the pattern there is nothing to tell apart: no prior needed.
      const double distance = candidates.size() == 1 ? 0.0
                              : predicted            ? cv::norm(cv::Point2d(centre) - *predicted)
                                                     : std::numeric_limits<double>::max();
      pairs.emplace_back(distance, f, c);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<bool> foundUsed(found.size(), false), candidateUsed(candidates.size(), false);
  for (const auto& [distance, f, c] : pairs) {
    if (foundUsed[f] || candidateUsed[c]) continue;
    foundUsed[f] = candidateUsed[c] = true;
    sightings.push_back({candidates[c], std::move(found[f])});
  }
}

}  // namespace

std::vector<MarkerSighting> findGroundMarkers(const cv::Mat& gray, const MarkerLayout& layout,
                                              const CameraModel& model, const Pose& prior) {
  std::vector<MarkerSighting> sightings;
  // Boards grouped by pattern (columns, rows, square).
  std::map<std::tuple<int, int, double>, std::vector<std::size_t>> patterns;
  bool anyAruco = false;
  for (std::size_t m = 0; m < layout.markers.size(); ++m) {
    const auto& marker = layout.markers[m];
    if (marker.kind == MarkerKind::kAruco) {
      anyAruco = true;
      continue;
    }
    patterns[{marker.board.innerCorners.width, marker.board.innerCorners.height,
              marker.board.squareM}]
        .push_back(m);
  }
  for (const auto& [pattern, candidates] : patterns) {
    const cv::Size inner(std::get<0>(pattern), std::get<1>(pattern));
    matchBoards(findCheckerboards(gray, inner, static_cast<int>(candidates.size())), candidates,
                layout, model, prior, sightings);
  }
  if (anyAruco) {
    for (const auto& detection : findArucoMarkers(gray, layout.arucoDictionary)) {
      for (std::size_t m = 0; m < layout.markers.size(); ++m) {
        const auto& marker = layout.markers[m];
        if (marker.kind != MarkerKind::kAruco || marker.arucoId != detection.id) continue;
        sightings.push_back({m, {detection.corners.begin(), detection.corners.end()}});
      }
    }
  }
  std::sort(sightings.begin(), sightings.end(),
            [](const auto& a, const auto& b) { return a.marker < b.marker; });
  return sightings;
}

std::vector<PointCorrespondence> correspondencesOf(const MarkerLayout& layout,
                                                   const std::vector<MarkerSighting>& sightings) {
  std::vector<PointCorrespondence> points;
  for (const auto& sighting : sightings) {
    const auto& marker = layout.markers[sighting.marker];
    const auto corners = marker.corners();
    for (std::size_t k = 0; k < corners.size(); ++k) {
      points.push_back({cv::Vec3d(corners[k]), cv::Point2d(sighting.pixels[k]),
                        fmt::format("{} corner {}", marker.name, k)});
    }
  }
  return points;
}

}  // namespace surroundd::processing
