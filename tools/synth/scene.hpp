#pragma once
// The procedural world the synthetic cameras look at, built once from a seed: a flat textured
// ground (asphalt with lane markings, parking bays and a crosswalk), car-sized boxes beside the
// vehicle's path, a yard of textured facades around it, and a sky with clouds. The scene is static
// in the world frame (see vehicle_path.hpp); cameras move with the vehicle.
//
// Radiance is returned as BGR floats on the 0..255 scale of an 8-bit image ("linear-ish": the
// photometric model applies gain, white balance, gamma and noise on top of it).

#include <array>
#include <bit>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "tools/synth/mip_texture.hpp"

namespace surroundd::synth {

enum class Surface : std::uint8_t { kGround, kBox, kWall, kSky };

// kNearObjects adds, around the vehicle's start pose, crates and a wall 1-3 m from a car-sized body
// in the seam directions (+-45 and +-135 degrees azimuth): parallax at the seams, for measuring
// colour correction and masking where objects stand close. The vehicle drives on past them.
enum class SceneLayout { kDefault, kNearObjects };

struct Hit {
  Surface surface = Surface::kSky;
  float distance = 0;  // along the (unit) ray, metres; infinite for the sky
  int index = -1;      // box or wall index
};

// A car-sized box standing on the ground, its own x along its length.
struct SceneBox {
  cv::Point2f centre;  // world, metres
  float yaw = 0;       // radians
  float cosYaw = 1, sinYaw = 0;
  cv::Vec3f halfSize;        // half length, half width, full height (metres)
  cv::Vec3f colour;          // BGR albedo, 0..255
  int pattern = 0;           // which face gets stripes and which the checker
  float boundingRadius = 0;  // sphere around the box centre at half height
};

// Axis-aligned yard walls facing inwards: x = xMin / xMax, y = yMin / yMax.
struct SceneWalls {
  float xMin = -20, xMax = 20, yMin = -20, yMax = 20;
  std::array<float, 4> height{};    // order: xMax, xMin, yMax, yMin
  std::array<cv::Vec3f, 4> tint{};  // per-wall colour multiplier
};

// One ray to shade, with what the caller may already know about it.
struct RayQuery {
  cv::Vec3f origin;             // world, metres
  cv::Vec3f direction;          // world, unit length
  float pixelAngle = 1e-3f;     // angular size of the pixel, radians (texture filtering)
  float groundDistance = -1;    // distance to z = 0 along the ray if known (< 0: compute)
  float groundLod = -1;         // ground mip level if known (< 0: compute)
  std::uint32_t boxMask = ~0U;  // boxes that may be hit (bit i = box i); a superset is fine
};

class Scene {
 public:
  static constexpr int kGroundSize = 4096;  // texels: the ground repeats every 81.92 m
  static constexpr float kGroundTexelM = 0.02f;
  static constexpr float kFacadeTexelM = 0.01f;
  static constexpr int kMaxBoxes = 32;

  // `seconds`: how long the recording runs, so the yard is placed around the whole drive.
  Scene(std::uint64_t seed, double seconds, SceneLayout layout = SceneLayout::kDefault);

  // Radiance along a ray (BGR, 0..255).
  cv::Vec3f radiance(const RayQuery& query) const;
  // What a ray hits first (no shading): for tests and occlusion checks.
  Hit intersect(const cv::Vec3f& origin, const cv::Vec3f& direction) const;

  // The ground's albedo at a world point, filtered to a footprint of `footprintM` metres
  // (0: the finest level). Lets tests ask "which texel is here".
  cv::Vec3f groundColour(cv::Point2d worldXY, double footprintM = 0) const;
  // Mip level for a footprint on the ground, in metres.
  static float groundLod(float footprintM) {
    return footprintM <= kGroundTexelM ? 0.0f : fastLog2(footprintM * (1 / kGroundTexelM));
  }
  // log2 to about 0.005 for x > 0: mip selection does not need libm's precision or cost.
  static float fastLog2(float x) {
    const auto bits = std::bit_cast<std::uint32_t>(x);
    const float m = std::bit_cast<float>((bits & 0x007fffffU) | 0x3f800000U) - 1;  // mantissa - 1
    return static_cast<float>(static_cast<int>(bits >> 23) - 127) + m * (1.3465f - 0.3465f * m);
  }
  // Mip level for a pixel of angular size `pixelAngle` whose ray meets the ground after `distance`
  // with vertical direction component `dirZ`. The footprint's long axis decides (as OpenGL does):
  // blurrier at grazing angles, but never aliased.
  static float groundLodFor(float distance, float pixelAngle, float dirZ) {
    const float slant = dirZ < 0 ? -dirZ : dirZ;
    return groundLod(distance * pixelAngle / (slant > 0.05f ? slant : 0.05f));
  }

  // The renderer's fast path for the common pixel: ground, no box possibly in the way, hit point
  // inside the yard (so no wall in front either). Everything else goes through radiance().
  bool insideYard(float x, float y) const {
    return x > walls_.xMin && x < walls_.xMax && y > walls_.yMin && y < walls_.yMax;
  }
  cv::Vec3f groundAt(float x, float y, float lod) const {
    constexpr float kHalf = kGroundSize / 2;
    return ground_.sample(x * (1 / kGroundTexelM) + kHalf, y * (1 / kGroundTexelM) + kHalf, lod);
  }

  // Brightness factor of a surface facing `normal` (world frame, unit) under the fixed sun.
  static float sunShading(const cv::Vec3f& normal);

  const std::vector<SceneBox>& boxes() const { return boxes_; }
  const SceneWalls& walls() const { return walls_; }

 private:
  cv::Vec3f shadeBox(const SceneBox& box, const cv::Vec3f& origin, const cv::Vec3f& direction,
                     float distance, float footprint) const;
  cv::Vec3f shadeWall(int wall, const cv::Vec3f& point, const cv::Vec3f& direction, float distance,
                      float pixelAngle) const;
  cv::Vec3f shadeSky(const cv::Vec3f& direction) const;
  Hit trace(const RayQuery& query) const;
  // Nearest box hit along the ray among `mask`; index -1 when none.
  int nearestBox(const cv::Vec3f& origin, const cv::Vec3f& direction, std::uint32_t mask,
                 float& distance) const;
  // Distance to the yard wall the ray leaves through, and which wall.
  float wallDistance(const cv::Vec3f& origin, const cv::Vec3f& direction, int& wall) const;

  MipTexture ground_;
  MipTexture facade_;
  MipTexture clouds_;
  std::vector<SceneBox> boxes_;
  SceneWalls walls_;
  std::array<cv::Vec3f, 4> wallColour_{};  // tint times the sun's shading of each wall
};

}  // namespace surroundd::synth
