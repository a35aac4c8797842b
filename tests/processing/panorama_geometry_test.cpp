// The panorama's pixel grid and the bowl: directions round-trip through pixels, DESIGN.md's
// orientation holds, and rays meet the bowl on its surface.

#include "processing/panorama_geometry.hpp"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "processing/bowl_shape.hpp"

namespace surroundd::processing {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(PanoramaGeometry, PixelsAndDirectionsRoundTrip) {
  PanoramaGeometry geometry;
  geometry.size = {1000, 300};
  for (double v = 0; v < 300; v += 7.3) {
    for (double u = 0; u < 1000; u += 13.7) {
      const cv::Point2d back = geometry.pixel(geometry.direction({u, v}));
      EXPECT_NEAR(back.x, u, 1e-9);
      EXPECT_NEAR(back.y, v, 1e-9);
    }
  }
}

TEST(PanoramaGeometry, FollowsTheDesignConventions) {
  PanoramaGeometry geometry;
  geometry.size = {360, 90};
  geometry.elevationTopRad = kPi / 6;
  geometry.elevationBottomRad = -kPi / 3;
  // Column centres: -179.5 deg first; straight ahead between columns 179 and 180.
  EXPECT_NEAR(geometry.azimuth(0), -kPi + kPi / 360, 1e-12);
  EXPECT_NEAR(geometry.column(0), 179.5, 1e-9);
  EXPECT_NEAR(geometry.row(kPi / 6), -0.5, 1e-9);   // top edge
  EXPECT_NEAR(geometry.row(-kPi / 3), 89.5, 1e-9);  // bottom edge
  const cv::Vec3d left = geometry.direction({geometry.column(kPi / 2), geometry.row(0)});
  EXPECT_NEAR(left[1], 1, 1e-12);  // positive azimuth turns left (+y)
  const cv::Vec3d up = geometry.direction({geometry.column(0), geometry.row(kPi / 12)});
  EXPECT_GT(up[2], 0);  // rows above the horizon look up
}

TEST(BowlShape, RaysMeetTheFloorTheWallAndTheCylinderAbove) {
  const BowlShape bowl{5.0, 10.0, 3.0};
  const cv::Vec3d centre(0, 0, 1.9);
  int floor = 0, wall = 0, above = 0;
  for (double elevation = -89; elevation < 89; elevation += 0.5) {
    for (double azimuth = -180; azimuth < 180; azimuth += 37) {
      const double e = elevation * kPi / 180;
      const double a = azimuth * kPi / 180;
      const cv::Vec3d direction(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
      const auto hit = bowl.intersect(centre, direction);
      ASSERT_TRUE(hit.has_value());
      // On the ray, in front of the centre ...
      const cv::Vec3d along = *hit - centre;
      EXPECT_NEAR(cv::norm(along.cross(direction)), 0, 1e-9);
      EXPECT_GT(along.dot(direction), 0);
      // ... and on the surface.
      const double r = std::hypot((*hit)[0], (*hit)[1]);
      if (r < 5.0 - 1e-9) {
        EXPECT_NEAR((*hit)[2], 0, 1e-9);
        ++floor;
      } else if (r < 10.0 - 1e-9) {
        EXPECT_NEAR((*hit)[2], bowl.height(r), 1e-9);
        EXPECT_GT((*hit)[2], 0);
        ++wall;
      } else {
        EXPECT_NEAR(r, 10.0, 1e-9);
        EXPECT_GE((*hit)[2], 3.0 - 1e-9);
        ++above;
      }
    }
  }
  EXPECT_GT(floor, 0);
  EXPECT_GT(wall, 0);
  EXPECT_GT(above, 0);
  EXPECT_NEAR(bowl.height(7.5), 0.75, 1e-12);  // a quarter of the rim height halfway up
  EXPECT_FALSE(bowl.intersect(centre, {0, 0, 1}).has_value());
  EXPECT_EQ(*bowl.intersect(centre, {0, 0, -1}), cv::Vec3d(0, 0, 0));
}

}  // namespace
}  // namespace surroundd::processing
