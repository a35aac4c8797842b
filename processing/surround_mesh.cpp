#include "processing/surround_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <stdexcept>

#include <fmt/core.h>

namespace surroundd::processing {
namespace {

// A surface of revolution about the vertical axis through the panorama centre, given by its
// profile: q in [begin, end] -> (distance from the axis, height above the ground), walked from the
// inside (the panorama's bottom elevation) outwards and up (its top elevation).
struct Profile {
  std::function<cv::Vec2d(double)> at;
  double begin = 0;
  double end = 0;
};

// The profile parameters of rings+1 points at equal arc length along the profile, so that the
// triangles are of even size along the surface whatever its shape.
std::vector<double> ringParameters(const Profile& profile, int rings) {
  constexpr int kSamples = 4096;
  std::vector<double> length(kSamples + 1, 0.0);
  const double step = (profile.end - profile.begin) / kSamples;
  for (int k = 1; k <= kSamples; ++k) {
    const double q = profile.begin + k * step;
    length[k] = length[k - 1] + cv::norm(profile.at(q) - profile.at(q - step));
  }
  std::vector<double> parameters(static_cast<std::size_t>(rings) + 1);
  for (int i = 0; i <= rings; ++i) {
    const double wanted = length.back() * i / rings;
    const auto above = std::lower_bound(length.begin() + 1, length.end(), wanted);
    const auto k = static_cast<int>(std::min<std::ptrdiff_t>(above - length.begin(), kSamples));
    const double span = length[k] - length[k - 1];
    const double within = span > 0 ? (wanted - length[k - 1]) / span : 0.0;
    parameters[static_cast<std::size_t>(i)] = profile.begin + (k - 1 + within) * step;
  }
  parameters.front() = profile.begin;
  parameters.back() = profile.end;
  return parameters;
}

// Distance from the axis at which the ground is seen at `elevation` (< 0) from height h.
double groundRadius(double h, double elevation) { return h / std::tan(-elevation); }

Profile flatProfile(const MeshSettings& s, const PanoramaGeometry& p) {
  const double inner = groundRadius(p.centre[2], p.elevationBottomRad);
  if (inner >= s.flatRadiusM) {
    throw std::invalid_argument(fmt::format(
        "flat mesh: radius {:g} m is inside the ground the panorama cannot see ({:.2f} m)",
        s.flatRadiusM, inner));
  }
  return {[](double q) { return cv::Vec2d(q, 0); }, inner, s.flatRadiusM};
}

Profile sphereProfile(const MeshSettings& s, const PanoramaGeometry& p) {
  const double radius = s.sphereRadiusM;
  const double h = p.centre[2];
  return {
      [radius, h](double e) { return cv::Vec2d(radius * std::cos(e), h + radius * std::sin(e)); },
      p.elevationBottomRad, p.elevationTopRad};
}

// The bowl's floor, then its wall, then the cylinder above the rim, parametrized by q: the
// distance from the axis up to the rim, the rim plus the height above it beyond.
Profile bowlProfile(const MeshSettings& s, const PanoramaGeometry& p) {
  const BowlShape bowl = s.bowl;
  const auto at = [bowl](double q) {
    if (q <= bowl.rimRadiusM) return cv::Vec2d(q, bowl.height(q));
    return cv::Vec2d(bowl.rimRadiusM, bowl.rimHeightM + (q - bowl.rimRadiusM));
  };
  const cv::Vec3d origin(0, 0, p.centre[2]);
  const auto parameterOf = [&](double elevation) {
    const cv::Vec3d direction(std::cos(elevation), 0, std::sin(elevation));
    const cv::Vec3d point = *bowl.intersect(origin, direction);
    return point[0] < bowl.rimRadiusM ? point[0] : bowl.rimRadiusM + (point[2] - bowl.rimHeightM);
  };
  return {at, parameterOf(p.elevationBottomRad), parameterOf(p.elevationTopRad)};
}

Profile profileOf(const MeshSettings& s, const PanoramaGeometry& p) {
  switch (s.model) {
    case MeshModel::kFlat:
      return flatProfile(s, p);
    case MeshModel::kSphere360:
      return sphereProfile(s, p);
    case MeshModel::kBowl:
      return bowlProfile(s, p);
  }
  throw std::invalid_argument("unknown mesh model");
}

}  // namespace

SurroundMesh buildSurroundMesh(const MeshSettings& settings, const PanoramaGeometry& panorama) {
  if (settings.rings < 2 || settings.segments < 8) {
    throw std::invalid_argument(
        fmt::format("mesh: need at least 2 rings and 8 segments, got {} and {}", settings.rings,
                    settings.segments));
  }
  if (panorama.centre[2] <= 0 || panorama.elevationBottomRad >= 0) {
    throw std::invalid_argument(
        "mesh: the panorama centre must be above the ground and its bottom elevation below the "
        "horizon");
  }
  const Profile profile = profileOf(settings, panorama);
  const std::vector<double> rings = ringParameters(profile, settings.rings);
  const double top = panorama.elevationTopRad;
  const double span = top - panorama.elevationBottomRad;
  const auto columns = static_cast<std::uint32_t>(settings.segments) + 1;

  SurroundMesh mesh;
  mesh.vertices.reserve(rings.size() * columns);
  for (const double q : rings) {
    const cv::Vec2d rz = profile.at(q);
    const double elevation = std::atan2(rz[1] - panorama.centre[2], rz[0]);
    const auto v = static_cast<float>((top - elevation) / span);
    for (std::uint32_t j = 0; j < columns; ++j) {
      const double u = static_cast<double>(j) / settings.segments;
      const double azimuth = -std::numbers::pi + 2 * std::numbers::pi * u;
      mesh.vertices.push_back({{static_cast<float>(panorama.centre[0] + rz[0] * std::cos(azimuth)),
                                static_cast<float>(panorama.centre[1] + rz[0] * std::sin(azimuth)),
                                static_cast<float>(rz[1])},
                               {static_cast<float>(u), v}});
    }
  }
  mesh.innerRadiusM = profile.at(rings.front())[0];

  mesh.indices.reserve(static_cast<std::size_t>(settings.rings) * settings.segments * 6);
  for (std::uint32_t i = 0; i + 1 < rings.size(); ++i) {
    for (std::uint32_t j = 0; j + 1 < columns; ++j) {
      const std::uint32_t a = i * columns + j;
      const std::uint32_t b = a + 1;            // next azimuth
      const std::uint32_t c = a + columns + 1;  // next ring, next azimuth
      const std::uint32_t d = a + columns;      // next ring
      mesh.indices.insert(mesh.indices.end(), {a, b, c, a, c, d});
    }
  }
  return mesh;
}

}  // namespace surroundd::processing
