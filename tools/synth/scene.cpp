#include "tools/synth/scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <opencv2/imgproc.hpp>

#include "tools/synth/hash.hpp"
#include "tools/synth/scene_textures.hpp"
#include "tools/synth/vehicle_path.hpp"

namespace surroundd::synth {
namespace {

const cv::Size kFacadeSize(2048, 1024);  // 20.48 m wide (repeats), 10.24 m tall
constexpr float kInfinity = std::numeric_limits<float>::infinity();
constexpr std::uint64_t kLayoutStream = 11;
constexpr std::uint64_t kNearObjectsStream = 12;

// Fixed sun, so faces of boxes and walls differ in brightness as real surfaces do.
const cv::Vec3f kSun = cv::normalize(cv::Vec3f(0.45f, 0.3f, 0.84f));

float shadeFor(const cv::Vec3f& normal) { return 0.5f + 0.5f * std::max(0.0f, normal.dot(kSun)); }

// Fraction of [x - w/2, x + w/2] on the "on" half of a square wave of `period`: the stripe
// pattern box-filtered over the pixel footprint, so boxes stay free of aliasing at any range.
float filteredSquare(float x, float period, float width) {
  const auto integral = [period](float t) {
    const float cycles = std::floor(t / period);
    return cycles * period * 0.5f + std::min(t - cycles * period, period * 0.5f);
  };
  if (width < 1e-4f) return (x - std::floor(x / period) * period) < period * 0.5f ? 1.0f : 0.0f;
  return (integral(x + width * 0.5f) - integral(x - width * 0.5f)) / width;
}

cv::Vec3f hsvToBgr(double hue, double saturation, double value) {
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue, saturation, value));
  cv::Mat bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const auto px = bgr.at<cv::Vec3b>(0, 0);
  return {static_cast<float>(px[0]), static_cast<float>(px[1]), static_cast<float>(px[2])};
}

SceneWalls makeWalls(HashRng& rng, double seconds) {
  double xMin = 0, xMax = 0, yMin = 0, yMax = 0;
  for (double t = 0; t <= seconds + 0.25; t += 0.25) {
    const auto pose = VehiclePath::poseAt(t);
    xMin = std::min(xMin, pose.x);
    xMax = std::max(xMax, pose.x);
    yMin = std::min(yMin, pose.y);
    yMax = std::max(yMax, pose.y);
  }
  SceneWalls walls;
  walls.xMax = static_cast<float>(xMax + rng.uniform(12, 25));
  walls.xMin = static_cast<float>(xMin - rng.uniform(12, 25));
  walls.yMax = static_cast<float>(yMax + rng.uniform(12, 25));
  walls.yMin = static_cast<float>(yMin - rng.uniform(12, 25));
  for (std::size_t i = 0; i < 4; ++i) {
    walls.height[i] = static_cast<float>(rng.uniform(6, 10));
    walls.tint[i] = {static_cast<float>(rng.uniform(0.8, 1.15)),
                     static_cast<float>(rng.uniform(0.8, 1.15)),
                     static_cast<float>(rng.uniform(0.8, 1.15))};
  }
  return walls;
}

std::vector<SceneBox> makeBoxes(HashRng& rng, double seconds) {
  const int count = rng.integer(6, 10);
  const double hueOffset = rng.uniform(0, 180);
  // Spread along the drive (and a little before and after, so short recordings still see boxes).
  const double t0 = -6.0, t1 = std::max(seconds, 10.0) + 4.0;
  std::vector<SceneBox> boxes;
  for (int i = 0; i < count; ++i) {
    for (int attempt = 0; attempt < 64; ++attempt) {
      const double t = t0 + (t1 - t0) * (i + rng.uniform(0, 1)) / count;
      const auto pose = VehiclePath::poseAt(t);
      const double side = rng.uniform(0, 1) < 0.5 ? -1.0 : 1.0;
      const double offset = side * rng.uniform(3.5, 10.0);
      const cv::Vec3d centre = pose.toWorld({0, offset, 0});
      SceneBox box;
      box.centre = {static_cast<float>(centre[0]), static_cast<float>(centre[1])};
      const double turn = rng.uniform(0, 1) < 0.35 ? std::numbers::pi / 2 : 0.0;
      box.yaw = static_cast<float>(pose.yaw + turn + rng.uniform(-0.3, 0.3));
      box.cosYaw = std::cos(box.yaw);
      box.sinYaw = std::sin(box.yaw);
      box.halfSize = {static_cast<float>(rng.uniform(2.1, 2.4)),
                      static_cast<float>(rng.uniform(0.85, 0.95)),
                      static_cast<float>(rng.uniform(1.4, 1.6))};
      box.boundingRadius =
          std::sqrt(box.halfSize[0] * box.halfSize[0] + box.halfSize[1] * box.halfSize[1] +
                    box.halfSize[2] * box.halfSize[2] * 0.25f);
      const bool clear = std::all_of(boxes.begin(), boxes.end(), [&](const SceneBox& other) {
        return cv::norm(other.centre - box.centre) > 5.5;
      });
      if (!clear && attempt + 1 < 64) continue;
      // Distinct saturated hues, evenly spaced around the colour wheel. Value before saturation:
      // the order x86-64 builds drew them in (hash.hpp, HashRng).
      const double value = rng.uniform(170, 235);
      const double saturation = rng.uniform(190, 255);
      box.colour = hsvToBgr(std::fmod(hueOffset + 180.0 * i / count, 180.0), saturation, value);
      box.pattern = rng.integer(0, 1);
      boxes.push_back(box);
      break;
    }
  }
  return boxes;
}

SceneBox makeBox(cv::Point2d centre, double yaw, const cv::Vec3f& halfSize, const cv::Vec3f& colour,
                 int pattern) {
  SceneBox box;
  box.centre = {static_cast<float>(centre.x), static_cast<float>(centre.y)};
  box.yaw = static_cast<float>(yaw);
  box.cosYaw = std::cos(box.yaw);
  box.sinYaw = std::sin(box.yaw);
  box.halfSize = halfSize;
  box.boundingRadius = std::sqrt(halfSize[0] * halfSize[0] + halfSize[1] * halfSize[1] +
                                 halfSize[2] * halfSize[2] * 0.25f);
  box.colour = colour;
  box.pattern = pattern;
  return box;
}

// Crates at the seams and a wall along the left, placed around the start pose (where the world and
// the vehicle frame coincide), measured from a typical car's footprint so that they stand 1-3 m
// from the body of either preset rig.
std::vector<SceneBox> makeNearObjects(HashRng& rng) {
  const cv::Point2d carHalf(2.3, 0.95);
  const auto gapTo = [&](cv::Point2d p) {
    return std::hypot(std::max(std::abs(p.x) - carHalf.x, 0.0),
                      std::max(std::abs(p.y) - carHalf.y, 0.0));
  };
  std::vector<SceneBox> objects;
  const double wallGap = rng.uniform(2.3, 3.0);
  const float wallHeight = static_cast<float>(rng.uniform(2.0, 2.6));
  objects.push_back(makeBox({0, carHalf.y + wallGap + 0.1}, 0, {5.0f, 0.1f, wallHeight},
                            cv::Vec3f(150, 155, 160), 1));
  // The left crates stand between the car and the wall.
  const std::array<std::pair<double, double>, 4> seams{
      {{45, 1.4}, {135, 1.4}, {-45, 3.0}, {-135, 3.0}}};  // azimuth (degrees), widest gap (m)
  for (const auto& [azimuthDeg, widestGap] : seams) {
    const double azimuth = (azimuthDeg + rng.uniform(-2, 2)) * std::numbers::pi / 180;
    // Height, width, then length: the order x86-64 builds drew them in (hash.hpp, HashRng).
    const auto height = static_cast<float>(rng.uniform(0.8, 1.5));
    const auto halfWidth = static_cast<float>(rng.uniform(0.25, 0.35));
    const auto halfLength = static_cast<float>(rng.uniform(0.25, 0.35));
    const cv::Vec3f half(halfLength, halfWidth, height);
    // Out along the seam until the crate's near side is `gap` from the car.
    const double gap = rng.uniform(1.0, widestGap) + half[0];
    double lo = 0, hi = 20;
    for (int i = 0; i < 40; ++i) {
      const double mid = (lo + hi) / 2;
      (gapTo(mid * cv::Point2d(std::cos(azimuth), std::sin(azimuth))) < gap ? lo : hi) = mid;
    }
    // Pattern, value, saturation, hue, then yaw: the order x86-64 builds drew them in (hash.hpp).
    const int pattern = rng.integer(0, 1);
    const double value = rng.uniform(150, 220);
    const double saturation = rng.uniform(150, 230);
    const double hue = rng.uniform(0, 180);
    const double yaw = azimuth + rng.uniform(-0.3, 0.3);
    objects.push_back(makeBox(hi * cv::Point2d(std::cos(azimuth), std::sin(azimuth)), yaw, half,
                              hsvToBgr(hue, saturation, value), pattern));
  }
  return objects;
}

}  // namespace

float Scene::sunShading(const cv::Vec3f& normal) { return shadeFor(normal); }

Scene::Scene(std::uint64_t seed, double seconds, SceneLayout layout)
    : ground_(makeGroundTexture(seed, kGroundSize, kGroundTexelM)),
      facade_(makeFacadeTexture(seed, kFacadeSize, kFacadeTexelM)),
      clouds_(makeCloudTexture(seed, 256)) {
  HashRng rng(seed, kLayoutStream);
  walls_ = makeWalls(rng, seconds);
  boxes_ = makeBoxes(rng, seconds);
  if (layout == SceneLayout::kNearObjects) {
    HashRng near(seed, kNearObjectsStream);
    const auto objects = makeNearObjects(near);
    // The drive's boxes make way for them.
    std::erase_if(boxes_, [&](const SceneBox& box) {
      return std::any_of(objects.begin(), objects.end(), [&](const SceneBox& object) {
        return cv::norm(box.centre - object.centre) <
               box.boundingRadius + object.boundingRadius + 0.3;
      });
    });
    boxes_.insert(boxes_.end(), objects.begin(), objects.end());
  }
  static const std::array<cv::Vec3f, 4> kNormals{cv::Vec3f(-1, 0, 0), cv::Vec3f(1, 0, 0),
                                                 cv::Vec3f(0, -1, 0), cv::Vec3f(0, 1, 0)};
  for (std::size_t w = 0; w < 4; ++w) wallColour_[w] = walls_.tint[w] * shadeFor(kNormals[w]);
}

cv::Vec3f Scene::groundColour(cv::Point2d worldXY, double footprintM) const {
  return groundAt(static_cast<float>(worldXY.x), static_cast<float>(worldXY.y),
                  groundLod(static_cast<float>(footprintM)));
}

float Scene::wallDistance(const cv::Vec3f& o, const cv::Vec3f& d, int& wall) const {
  float tx = kInfinity, ty = kInfinity;
  int wx = 0, wy = 2;
  if (d[0] > 0) tx = (walls_.xMax - o[0]) / d[0];
  if (d[0] < 0) tx = (walls_.xMin - o[0]) / d[0], wx = 1;
  if (d[1] > 0) ty = (walls_.yMax - o[1]) / d[1];
  if (d[1] < 0) ty = (walls_.yMin - o[1]) / d[1], wy = 3;
  wall = tx < ty ? wx : wy;
  return std::min(tx, ty);
}

int Scene::nearestBox(const cv::Vec3f& o, const cv::Vec3f& d, std::uint32_t mask,
                      float& distance) const {
  int nearest = -1;
  for (std::size_t i = 0; mask != 0 && i < boxes_.size(); ++i, mask >>= 1) {
    if ((mask & 1U) == 0) continue;
    const SceneBox& b = boxes_[i];
    // Ray in the box's frame: turn by -yaw about the box centre.
    const float rx = o[0] - b.centre.x, ry = o[1] - b.centre.y;
    const float lox = b.cosYaw * rx + b.sinYaw * ry, loy = -b.sinYaw * rx + b.cosYaw * ry;
    const float ldx = b.cosYaw * d[0] + b.sinYaw * d[1], ldy = -b.sinYaw * d[0] + b.cosYaw * d[1];
    const float ix = 1 / ldx, iy = 1 / ldy, iz = 1 / d[2];
    float ax = (-b.halfSize[0] - lox) * ix, bx = (b.halfSize[0] - lox) * ix;
    float ay = (-b.halfSize[1] - loy) * iy, by = (b.halfSize[1] - loy) * iy;
    float az = (0 - o[2]) * iz, bz = (b.halfSize[2] - o[2]) * iz;
    const float tNear = std::max({std::min(ax, bx), std::min(ay, by), std::min(az, bz)});
    const float tFar = std::min({std::max(ax, bx), std::max(ay, by), std::max(az, bz)});
    if (tNear <= tFar && tNear > 0 && tNear < distance) {
      distance = tNear;
      nearest = static_cast<int>(i);
    }
  }
  return nearest;
}

Hit Scene::trace(const RayQuery& q) const {
  const cv::Vec3f& o = q.origin;
  const cv::Vec3f& d = q.direction;
  Hit hit;
  hit.distance =
      q.groundDistance >= 0 ? q.groundDistance : (d[2] < 0 && o[2] > 0 ? -o[2] / d[2] : kInfinity);
  hit.surface = std::isfinite(hit.distance) ? Surface::kGround : Surface::kSky;
  // A ground point inside the yard is nearer than any wall (the yard is convex and holds the
  // origin), which saves the wall test for most pixels.
  bool wallPossible = true;
  if (hit.surface == Surface::kGround) {
    const float x = o[0] + hit.distance * d[0];
    const float y = o[1] + hit.distance * d[1];
    wallPossible = !(x > walls_.xMin && x < walls_.xMax && y > walls_.yMin && y < walls_.yMax);
  }
  if (wallPossible) {
    int wall = 0;
    const float t = wallDistance(o, d, wall);
    if (t < hit.distance && o[2] + t * d[2] < walls_.height[static_cast<std::size_t>(wall)]) {
      hit = {Surface::kWall, t, wall};
    }
  }
  if (q.boxMask != 0) {
    float t = hit.distance;
    const int box = nearestBox(o, d, q.boxMask, t);
    if (box >= 0) hit = {Surface::kBox, t, box};
  }
  return hit;
}

Hit Scene::intersect(const cv::Vec3f& origin, const cv::Vec3f& direction) const {
  RayQuery query;
  query.origin = origin;
  query.direction = direction;
  return trace(query);
}

cv::Vec3f Scene::radiance(const RayQuery& q) const {
  const Hit hit = trace(q);
  switch (hit.surface) {
    case Surface::kGround: {
      const float lod =
          q.groundLod >= 0 ? q.groundLod : groundLodFor(hit.distance, q.pixelAngle, q.direction[2]);
      return groundAt(q.origin[0] + hit.distance * q.direction[0],
                      q.origin[1] + hit.distance * q.direction[1], lod);
    }
    case Surface::kBox:
      return shadeBox(boxes_[static_cast<std::size_t>(hit.index)], q.origin, q.direction,
                      hit.distance, hit.distance * q.pixelAngle);
    case Surface::kWall:
      return shadeWall(hit.index, q.origin + hit.distance * q.direction, q.direction, hit.distance,
                       q.pixelAngle);
    case Surface::kSky:
      break;
  }
  return shadeSky(q.direction);
}

cv::Vec3f Scene::shadeBox(const SceneBox& b, const cv::Vec3f& o, const cv::Vec3f& d, float distance,
                          float footprint) const {
  const cv::Vec3f p = o + distance * d;
  const float rx = p[0] - b.centre.x, ry = p[1] - b.centre.y;
  const float lx = b.cosYaw * rx + b.sinYaw * ry, ly = -b.sinYaw * rx + b.cosYaw * ry;
  const float lz = p[2];
  // The face is the one the hit point lies on (largest coordinate relative to the half size).
  const float ex = std::abs(lx) / b.halfSize[0], ey = std::abs(ly) / b.halfSize[1];
  const float ez = lz / b.halfSize[2];
  float pattern = 1;
  cv::Vec3f normalLocal;
  const bool stripesOnEnds = b.pattern == 0;
  if (ez >= ex && ez >= ey) {  // roof: diagonal stripes
    normalLocal = {0, 0, 1};
    pattern = filteredSquare((lx + ly) * 0.7071f, 0.5f, footprint);
  } else if (ex >= ey) {  // ends
    normalLocal = {lx > 0 ? 1.0f : -1.0f, 0, 0};
    pattern =
        stripesOnEnds
            ? filteredSquare(lz, 0.3f, footprint)
            : std::abs(filteredSquare(ly, 0.6f, footprint) - filteredSquare(lz, 0.6f, footprint));
  } else {  // long sides
    normalLocal = {0, ly > 0 ? 1.0f : -1.0f, 0};
    pattern =
        stripesOnEnds
            ? std::abs(filteredSquare(lx, 0.6f, footprint) - filteredSquare(lz, 0.6f, footprint))
            : filteredSquare(lx, 0.4f, footprint);
  }
  const cv::Vec3f normal(b.cosYaw * normalLocal[0] - b.sinYaw * normalLocal[1],
                         b.sinYaw * normalLocal[0] + b.cosYaw * normalLocal[1], normalLocal[2]);
  // A dark band along the bottom, like tyres and sills.
  const float sill = lz < 0.35f ? 0.35f : 1.0f;
  return b.colour * (shadeFor(normal) * sill * (0.55f + 0.45f * pattern));
}

cv::Vec3f Scene::shadeWall(int wall, const cv::Vec3f& p, const cv::Vec3f& d, float distance,
                           float pixelAngle) const {
  // Walls face inwards; the texture runs left to right as seen from inside the yard.
  const auto w = static_cast<std::size_t>(wall);
  const float along = wall == 0 ? p[1] : wall == 1 ? -p[1] : wall == 2 ? -p[0] : p[0];
  // |d . normal| for an axis-aligned wall is one component of d.
  const float incidence = std::max(std::abs(wall < 2 ? d[0] : d[1]), 0.1f);
  const float footprint = distance * pixelAngle / incidence;
  const float lod = footprint <= kFacadeTexelM ? 0 : fastLog2(footprint / kFacadeTexelM);
  return facade_.sample(along / kFacadeTexelM, p[2] / kFacadeTexelM, lod).mul(wallColour_[w]);
}

cv::Vec3f Scene::shadeSky(const cv::Vec3f& d) const {
  const float up = std::max(d[2], 0.0f);
  const cv::Vec3f horizon(232, 218, 204), zenith(205, 150, 95);
  const cv::Vec3f base = horizon + (zenith - horizon) * std::sqrt(up);
  // Clouds on a plane high above, thinning out towards the hazy horizon.
  const float scale = 48.0f / (up + 0.08f);
  const float density = clouds_.bilinear(0, d[0] * scale, d[1] * scale)[0] / 255.0f;
  const float cover = std::clamp((density - 0.48f) * 4.0f, 0.0f, 1.0f) * std::min(up * 6, 1.0f);
  return base + (cv::Vec3f(246, 246, 246) - base) * cover;
}

}  // namespace surroundd::synth
