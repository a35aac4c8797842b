#pragma once
// The spherical panorama's pixel grid (DESIGN.md §4): column 0 starts at azimuth -pi, azimuth 0 is
// straight ahead (+x) and positive azimuth turns left (+y); row 0 starts at the top elevation.
// Pixel centres sit at integer coordinates, so pixel (u, v) is the direction at
//   azimuth   = -pi + (u + 0.5) * 2 pi / width
//   elevation = top - (v + 0.5) * (top - bottom) / height.
// Directions are seen from `centre`, the panorama's projection centre in the vehicle frame.

#include <cmath>
#include <numbers>

#include <opencv2/core.hpp>

namespace surroundd::processing {

struct PanoramaGeometry {
  cv::Size size{2048, 1024};
  double elevationTopRad = std::numbers::pi / 6;
  double elevationBottomRad = -std::numbers::pi / 3;
  cv::Vec3d centre{0, 0, 1.9};  // on the vehicle's z axis (x = y = 0), metres above the ground

  double azimuth(double column) const {
    return -std::numbers::pi + (column + 0.5) * 2 * std::numbers::pi / size.width;
  }
  double elevation(double row) const {
    return elevationTopRad - (row + 0.5) * (elevationTopRad - elevationBottomRad) / size.height;
  }
  double column(double azimuthRad) const {
    return (azimuthRad + std::numbers::pi) * size.width / (2 * std::numbers::pi) - 0.5;
  }
  double row(double elevationRad) const {
    return (elevationTopRad - elevationRad) * size.height / (elevationTopRad - elevationBottomRad) -
           0.5;
  }
  double pixelsPerRadian() const { return size.width / (2 * std::numbers::pi); }

  // Unit direction of a (sub-)pixel in the vehicle frame.
  cv::Vec3d direction(const cv::Point2d& pixel) const {
    const double a = azimuth(pixel.x);
    const double e = elevation(pixel.y);
    return {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
  }
  // Pixel of a direction (need not be unit); columns wrap into [-0.5, width - 0.5).
  cv::Point2d pixel(const cv::Vec3d& direction) const {
    const double a = std::atan2(direction[1], direction[0]);
    const double e = std::atan2(direction[2], std::hypot(direction[0], direction[1]));
    return {column(a), row(e)};
  }

  bool operator==(const PanoramaGeometry&) const = default;
};

}  // namespace surroundd::processing
