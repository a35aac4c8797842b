#include "processing/vehicle_body.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "common/work_pool.hpp"

namespace surroundd::processing {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Even-odd rule: a footprint may be concave (a pickup's bed, a bus's mirrors).
bool insidePolygon(std::span<const cv::Point2d> polygon, const cv::Point2d& p) {
  bool inside = false;
  for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const cv::Point2d& a = polygon[i];
    const cv::Point2d& b = polygon[j];
    if ((a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x) {
      inside = !inside;
    }
  }
  return inside;
}

}  // namespace

bool VehicleBody::blocks(const cv::Vec3d& origin, const cv::Vec3d& direction) const {
  // The span of t where the ray is between underside and roof.
  double zFirst = -kInfinity;
  double zLast = kInfinity;
  if (std::abs(direction[2]) < 1e-12) {
    if (origin[2] < clearanceM || origin[2] > heightM) return false;
  } else {
    const double a = (clearanceM - origin[2]) / direction[2];
    const double b = (heightM - origin[2]) / direction[2];
    zFirst = std::min(a, b);
    zLast = std::max(a, b);
  }
  const double first = std::max(zFirst, kLensClearanceM);
  if (first >= zLast) return false;

  // Where the ray's plan view crosses the footprint's edges; inside-ness flips at each.
  const cv::Point2d o(origin[0], origin[1]);
  const cv::Point2d d(direction[0], direction[1]);
  std::array<double, 64> crossings{};
  std::size_t count = 0;
  for (std::size_t i = 0, j = footprint.size() - 1; i < footprint.size() && count < 64; j = i++) {
    const cv::Point2d e = footprint[i] - footprint[j];
    const double denominator = d.x * e.y - d.y * e.x;
    if (std::abs(denominator) < 1e-15) continue;  // parallel to the edge
    const cv::Point2d w = footprint[j] - o;
    const double t = (w.x * e.y - w.y * e.x) / denominator;
    const double s = (w.x * d.y - w.y * d.x) / denominator;
    if (s >= 0 && s < 1 && t > 0) crossings[count++] = t;
  }
  std::sort(crossings.begin(), crossings.begin() + static_cast<std::ptrdiff_t>(count));
  bool inside = insidePolygon(footprint, o);
  double from = 0;
  for (std::size_t k = 0; k <= count; ++k) {
    const double to = k < count ? crossings[k] : kInfinity;
    if (inside && std::max(from, first) < std::min(to, zLast)) return true;
    inside = !inside;
    from = to;
  }
  return false;
}

VehicleBody boxBody(double lengthM, double widthM, double heightM, double clearanceM,
                    const cv::Point2d& centre) {
  const double x = lengthM / 2;
  const double y = widthM / 2;
  return {{centre + cv::Point2d(x, y), centre + cv::Point2d(-x, y), centre + cv::Point2d(-x, -y),
           centre + cv::Point2d(x, -y)},
          clearanceM,
          heightM};
}

cv::Mat computeBodyMask(const VehicleBody& body, const CameraCalibration& camera, WorkPool& pool) {
  const CameraModel model(camera.intrinsics);
  const cv::Size size = camera.intrinsics.imageSize;
  cv::Mat mask(size, CV_8U, cv::Scalar(0));
  if (body.footprint.size() < 3) return mask;
  const cv::Vec3d origin = camera.pose.position;
  pool.parallelFor(
      size.height,
      [&](int first, int last) {
        for (int v = first; v < last; ++v) {
          auto* row = mask.ptr<std::uint8_t>(v);
          for (int u = 0; u < size.width; ++u) {
            const auto ray = model.unproject(cv::Point2d(u, v));
            if (ray && body.blocks(origin, camera.pose.rotation * *ray)) row[u] = 255;
          }
        }
      },
      pool.threads() * 4);
  return mask;
}

double maskIoU(const cv::Mat& a, const cv::Mat& b) {
  CV_Assert(a.size() == b.size() && a.type() == CV_8U && b.type() == CV_8U);
  const int both = cv::countNonZero(a & b);
  const int either = cv::countNonZero(a | b);
  return either == 0 ? 1.0 : static_cast<double>(both) / either;
}

}  // namespace surroundd::processing
