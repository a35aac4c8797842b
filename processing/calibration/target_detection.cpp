#include "processing/calibration/target_detection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace surroundd::processing {
namespace {

cv::TermCriteria subPixCriteria() {
  return {cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 50, 1e-4};
}

float sampleBilinear(const cv::Mat& gray, cv::Point2f p) {
  const int x0 = std::clamp(static_cast<int>(std::floor(p.x)), 0, gray.cols - 2);
  const int y0 = std::clamp(static_cast<int>(std::floor(p.y)), 0, gray.rows - 2);
  const float ax = std::clamp(p.x - static_cast<float>(x0), 0.0f, 1.0f);
  const float ay = std::clamp(p.y - static_cast<float>(y0), 0.0f, 1.0f);
  const auto at = [&](int x, int y) { return static_cast<float>(gray.at<std::uint8_t>(y, x)); };
  return (1 - ay) * ((1 - ax) * at(x0, y0) + ax * at(x0 + 1, y0)) +
         ay * ((1 - ax) * at(x0, y0 + 1) + ax * at(x0 + 1, y0 + 1));
}

// Mean brightness inside the square spanned by four corners: its centre and four points halfway to
// the corners, which stay clear of the blurred edges.
float squareBrightness(const cv::Mat& gray, cv::Point2f a, cv::Point2f b, cv::Point2f c,
                       cv::Point2f d) {
  const cv::Point2f centre = (a + b + c + d) * 0.25f;
  float sum = sampleBilinear(gray, centre);
  for (const auto& corner : {a, b, c, d}) sum += sampleBilinear(gray, (centre + corner) * 0.5f);
  return sum / 5;
}

// Puts a detected grid into the board's own order (calibration_targets.hpp). Of the four orders a
// W x H grid can be listed in, two are mirror images, which a board seen from its printed side
// never produces: the row direction turned towards the column direction must be clockwise in the
// image (y down). Of the other two, a half turn apart, the one whose square (1, 1), the first
// inner square, is black is right (see blackFirstScore()).
void orientBoard(std::vector<cv::Point2f>& corners, cv::Size inner, const cv::Mat& gray) {
  const std::ptrdiff_t w = inner.width;
  const cv::Point2f along = corners[1] - corners[0];
  const cv::Point2f across = corners[static_cast<std::size_t>(w)] - corners[0];
  if (along.cross(across) < 0) {
    for (auto row = corners.begin(); row != corners.end(); row += w) std::reverse(row, row + w);
  }
  if (blackFirstScore(gray, corners, inner) < 0) std::reverse(corners.begin(), corners.end());
}

// The board's outline two squares beyond its outer inner corners (its outer squares and white
// margin), extrapolated from the corner grid.
std::vector<cv::Point> boardOutline(const std::vector<cv::Point2f>& corners, cv::Size inner) {
  const int w = inner.width, h = inner.height;
  const auto at = [&](int i, int j) {
    return corners[static_cast<std::size_t>(j) * static_cast<std::size_t>(w) +
                   static_cast<std::size_t>(i)];
  };
  std::vector<cv::Point> outline;
  for (const auto& [i, j] : {std::pair{0, 0}, {w - 1, 0}, {w - 1, h - 1}, {0, h - 1}}) {
    const int di = i == 0 ? 1 : -1, dj = j == 0 ? 1 : -1;
    const cv::Point2f p = at(i, j);
    outline.emplace_back(p + 2 * (p - at(i + di, j)) + 2 * (p - at(i, j + dj)));
  }
  return outline;
}

}  // namespace

float blackFirstScore(const cv::Mat& gray, std::span<const cv::Point2f> corners, cv::Size inner) {
  const auto at = [&](int i, int j) {
    return corners[static_cast<std::size_t>(j) * static_cast<std::size_t>(inner.width) +
                   static_cast<std::size_t>(i)];
  };
  // Every inner square votes, for robustness against glare.
  float oddMinusEven = 0;
  for (int j = 0; j + 1 < inner.height; ++j) {
    for (int i = 0; i + 1 < inner.width; ++i) {
      const float b =
          squareBrightness(gray, at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
      oddMinusEven += (i + j) % 2 == 0 ? -b : b;
    }
  }
  return oddMinusEven / static_cast<float>((inner.width - 1) * (inner.height - 1));
}

double smallestGridStep(std::span<const cv::Point2f> corners, cv::Size inner) {
  const auto w = static_cast<std::size_t>(inner.width);
  double smallest = std::numeric_limits<double>::max();
  for (std::size_t i = 0; i < corners.size(); ++i) {
    if ((i + 1) % w != 0) smallest = std::min(smallest, cv::norm(corners[i + 1] - corners[i]));
    if (i + w < corners.size())
      smallest = std::min(smallest, cv::norm(corners[i + w] - corners[i]));
  }
  return smallest;
}

std::optional<std::vector<cv::Point2f>> findCheckerboard(const cv::Mat& gray, cv::Size inner) {
  std::vector<cv::Point2f> corners;
  // The sector-based detector finds boards more reliably (noise, blur, lens distortion), the
  // classic one some small boards it misses. Neither's corners are the most accurate: on rendered
  // boards with known truth, cornerSubPix with a window as large as the squares allow halved the
  // error of the sector-based detector's own sub-pixel positions (0.06 px against 0.13 px, which
  // were biased outwards enough to shift focal lengths by 0.4 %).
  if (!cv::findChessboardCornersSB(gray, inner, corners,
                                   cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_EXHAUSTIVE) &&
      !cv::findChessboardCorners(gray, inner, corners,
                                 cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
    return std::nullopt;
  }
  refineCheckerboardCorners(gray, corners, inner);
  orientBoard(corners, inner, gray);
  return corners;
}

void refineCheckerboardCorners(const cv::Mat& gray, std::vector<cv::Point2f>& corners,
                               cv::Size grid) {
  // The largest window that stays inside one square: 0.4 of the smallest square.
  const int half = std::clamp(static_cast<int>(smallestGridStep(corners, grid) * 0.4), 2, 11);
  cv::cornerSubPix(gray, corners, {half, half}, {-1, -1}, subPixCriteria());
}

std::vector<std::vector<cv::Point2f>> findCheckerboards(const cv::Mat& gray, cv::Size inner,
                                                        int maxCount) {
  std::vector<std::vector<cv::Point2f>> boards;
  cv::Mat remaining = gray.clone();
  while (static_cast<int>(boards.size()) < maxCount) {
    auto corners = findCheckerboard(remaining, inner);
    if (!corners) break;
    const auto outline = boardOutline(*corners, inner);
    cv::fillConvexPoly(remaining, outline, cv::Scalar(cv::mean(gray)[0]), cv::LINE_AA);
    boards.push_back(std::move(*corners));
  }
  return boards;
}

std::vector<ArucoDetection> findArucoMarkers(const cv::Mat& gray, int dictionary) {
  const auto dict = cv::aruco::getPredefinedDictionary(dictionary);
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  // OpenCV's own refinement uses one window for every marker: on a small marker it reaches the
  // code's inner corners and settles there, a module off (2 px on the rendered tests). Refined
  // below with a window of 0.6 modules, which stays within the border module and the quiet zone:
  // 0.25 px on the same tests (OpenCV's contour and AprilTag refinements: 0.7 px).
  const auto parameters = cv::aruco::DetectorParameters::create();
  parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;
  cv::aruco::detectMarkers(gray, dict, corners, ids, parameters);
  std::vector<ArucoDetection> found;
  const float modules = static_cast<float>(dict->markerSize + 2);
  for (std::size_t k = 0; k < ids.size(); ++k) {
    auto& c = corners[k];
    double shortestSide = 1e9;
    for (std::size_t i = 0; i < 4; ++i)
      shortestSide = std::min(shortestSide, cv::norm(c[(i + 1) % 4] - c[i]));
    const int half = std::clamp(static_cast<int>(shortestSide / modules * 0.6), 1, 11);
    cv::cornerSubPix(gray, c, {half, half}, {-1, -1}, subPixCriteria());
    ArucoDetection detection;
    detection.id = ids[k];
    std::copy_n(c.begin(), 4, detection.corners.begin());
    found.push_back(detection);
  }
  return found;
}

}  // namespace surroundd::processing
