// --scene near-objects: something stands 1-3 m from the car in each seam direction at the start,
// where the default scene has open ground.

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "tools/synth/scene.hpp"

namespace surroundd::synth {
namespace {

// From the middle of a typical car (the one the layout is measured from), half a metre up.
Hit seamRay(const Scene& scene, double azimuthDeg) {
  const double azimuth = azimuthDeg * std::numbers::pi / 180;
  return scene.intersect(cv::Vec3f(0, 0, 0.5), cv::Vec3f(static_cast<float>(std::cos(azimuth)),
                                                         static_cast<float>(std::sin(azimuth)), 0));
}

double gapToCar(const cv::Vec2d& p) {
  return std::hypot(std::max(std::abs(p[0]) - 2.3, 0.0), std::max(std::abs(p[1]) - 0.95, 0.0));
}

TEST(SynthSceneLayout, NearObjectsStandAtTheSeams) {
  constexpr std::uint64_t kSeed = 3;
  const Scene near(kSeed, 1.0, SceneLayout::kNearObjects);
  for (const double azimuth : {45.0, 135.0, -45.0, -135.0}) {
    const Hit hit = seamRay(near, azimuth);
    EXPECT_EQ(hit.surface, Surface::kBox) << azimuth;
    const double a = azimuth * std::numbers::pi / 180;
    const double gap = gapToCar({hit.distance * std::cos(a), hit.distance * std::sin(a)});
    EXPECT_GE(gap, 0.9) << azimuth;
    EXPECT_LE(gap, 3.1) << azimuth;
  }
  const Scene plain(kSeed, 1.0);
  for (const double azimuth : {45.0, 135.0, -45.0, -135.0}) {
    const Hit hit = seamRay(plain, azimuth);
    EXPECT_TRUE(hit.surface != Surface::kBox || hit.distance > 4.5) << azimuth;
  }
}

}  // namespace
}  // namespace surroundd::synth
