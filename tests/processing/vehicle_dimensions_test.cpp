// The one vehicle-dimensions type: the box a footprint polygon is drawn in, the wheels' track it
// defaults to, and how far the body reaches, against figures worked out by hand.

#include "processing/vehicle_dimensions.hpp"

#include <gtest/gtest.h>

namespace surroundd::processing {
namespace {

TEST(VehicleDimensions, TheBoxIsTheLengthAndWidthOrTheFootprintsBounds) {
  VehicleDimensions car;
  car.lengthM = 4.0;
  car.widthM = 2.0;
  car.xM = 1.0;
  auto box = car.box();
  EXPECT_DOUBLE_EQ(box.lengthM, 4.0);
  EXPECT_DOUBLE_EQ(box.widthM, 2.0);
  EXPECT_DOUBLE_EQ(box.centreXM, 1.0);
  EXPECT_DOUBLE_EQ(box.centreYM, 0.0);
  EXPECT_DOUBLE_EQ(car.wheelTrackM(), 1.75);  // the width less 0.25 m
  EXPECT_DOUBLE_EQ(car.reachM(), std::hypot(3.0, 1.0));
  EXPECT_EQ(car.body().footprint.size(), 4U);

  // A van's footprint, its length and width keys left at their defaults (ignored).
  car.footprint = {{-1.0, -1.0}, {4.0, -1.2}, {4.0, 1.0}, {-1.0, 0.8}};
  box = car.box();
  EXPECT_DOUBLE_EQ(box.lengthM, 5.0);
  EXPECT_DOUBLE_EQ(box.widthM, 2.2);
  EXPECT_DOUBLE_EQ(box.centreXM, 1.5);
  EXPECT_NEAR(box.centreYM, -0.1, 1e-12);
  EXPECT_DOUBLE_EQ(car.wheelTrackM(), 2.2 - 0.25);
  EXPECT_DOUBLE_EQ(car.reachM(), std::hypot(4.0, 1.2));
  EXPECT_EQ(car.body().footprint.size(), 4U);
  car.trackM = 1.5;
  EXPECT_DOUBLE_EQ(car.wheelTrackM(), 1.5);
  // A robot narrower than the default's 0.25 m keeps a track.
  car.footprint = {{0, 0}, {0.3, 0}, {0.3, 0.2}};
  car.trackM = 0;
  EXPECT_DOUBLE_EQ(car.wheelTrackM(), 0.1);
}

}  // namespace
}  // namespace surroundd::processing
