// The steering model behind the guidelines: every wheel turns about one centre on the rear
// axle's line, the way the vehicle goes with the steering and the gear; straight with the wheel
// straight.

#include "render/guidelines.hpp"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

namespace surroundd::render {
namespace {

const processing::VehicleDimensions kCar;  // 4.5 m, wheelbase 2.6 m, track 1.6 m, ratio 15

double rearAxleX() { return kCar.xM - kCar.lengthM / 2 + kCar.rearOverhangM; }

TEST(Guidelines, WithTheWheelStraightThePathsAreStraight) {
  for (const int side : {1, -1}) {
    const cv::Point2d start = wheelPathPoint(kCar, Travel::kReverse, 0, side, 0);
    EXPECT_DOUBLE_EQ(start.x, rearAxleX());
    EXPECT_DOUBLE_EQ(start.y, side * kCar.wheelTrackM() / 2);
    const cv::Point2d back = wheelPathPoint(kCar, Travel::kReverse, 0, side, -3);
    EXPECT_DOUBLE_EQ(back.x, rearAxleX() - 3);
    EXPECT_DOUBLE_EQ(back.y, start.y);
  }
}

TEST(Guidelines, EveryWheelTurnsAboutOneCentreOnTheRearAxleLine) {
  // 300 degrees at the wheel: 20 at the road wheels; the centre 2.6 / tan(20 deg) to the left.
  const double wheelbase = kCar.lengthM - kCar.frontOverhangM - kCar.rearOverhangM;
  const double radius = wheelbase / std::tan(20 * std::numbers::pi / 180);
  const cv::Point2d centre(rearAxleX(), radius);
  for (const Travel travel : {Travel::kReverse, Travel::kForward}) {
    for (const int side : {1, -1}) {
      const double start = cv::norm(wheelPathPoint(kCar, travel, 300, side, 0) - centre);
      for (const double distance : {-4.0, -1.0, 1.0, 4.0}) {
        EXPECT_NEAR(cv::norm(wheelPathPoint(kCar, travel, 300, side, distance) - centre), start,
                    1e-9);
      }
    }
  }
  // The rear wheels' circles are the track apart; the rear axle's centre turns on `radius`.
  EXPECT_NEAR(cv::norm(wheelPathPoint(kCar, Travel::kReverse, 300, -1, 0) - centre) -
                  cv::norm(wheelPathPoint(kCar, Travel::kReverse, 300, 1, 0) - centre),
              kCar.wheelTrackM(), 1e-9);
  // The rear axle's centre goes `distance` along its arc: 1 m is 1 / radius of a turn.
  const cv::Point2d left = wheelPathPoint(kCar, Travel::kReverse, 300, 1, -1);
  const double turned = std::atan2(left.x - centre.x, centre.y - left.y);
  EXPECT_NEAR(turned, -1 / radius, 1e-9);
}

// The wheel turned left: going forward the car goes left; reversing, its back goes left too (the
// front swings right), as a driver turns the wheel the way the back should go.
TEST(Guidelines, TheyBendTheWayTheCarGoes) {
  EXPECT_GT(wheelPathPoint(kCar, Travel::kForward, 200, 1, 3).y,
            wheelPathPoint(kCar, Travel::kForward, 0, 1, 3).y);
  EXPECT_GT(wheelPathPoint(kCar, Travel::kReverse, 200, 1, -3).y,
            wheelPathPoint(kCar, Travel::kReverse, 0, 1, -3).y);
  EXPECT_LT(wheelPathPoint(kCar, Travel::kReverse, -200, 1, -3).y,
            wheelPathPoint(kCar, Travel::kReverse, 0, 1, -3).y);
  // Past 45 degrees at the road wheels the lock holds.
  EXPECT_EQ(wheelPathPoint(kCar, Travel::kReverse, 15 * 45, 1, -2),
            wheelPathPoint(kCar, Travel::kReverse, 15 * 80, 1, -2));
}

TEST(Guidelines, TrianglesStayWithinTheReservedBuffer) {
  GuidelineSettings settings;
  settings.lengthM = 20;
  settings.markersM = {0.5, 1, 2, 4, 8, 12, 16, 20};
  settings.markerColours.assign(settings.markersM.size(), {1, 1, 1});
  processing::VehicleDimensions longest = kCar;
  longest.rearOverhangM = longest.frontOverhangM = 10;
  longest.lengthM = 25;
  std::vector<GuidelineVertex> vertices;
  vertices.reserve(maxGuidelineVertices(settings));
  const auto* buffer = vertices.data();
  for (const Travel travel : {Travel::kReverse, Travel::kForward}) {
    guidelines(longest, settings, travel, 540, vertices);
    EXPECT_EQ(vertices.data(), buffer);  // filled in place
    EXPECT_LE(vertices.size(), maxGuidelineVertices(settings));
    EXPECT_EQ(vertices.size() % 3, 0u);
  }
}

}  // namespace
}  // namespace surroundd::render
