#include "render/guidelines.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace surroundd::render {
namespace {

constexpr double kStepM = 0.05;          // between path points: smooth at the tightest turn
constexpr float kAboveGroundM = 0.03F;   // over the floor, under any kerb
constexpr double kMaxRoadWheelDeg = 45;  // beyond any car's lock

double rearAxleX(const processing::VehicleDimensions& car) {
  const auto box = car.box();
  return box.centreXM - box.lengthM / 2 + car.rearOverhangM;
}
double frontAxleX(const processing::VehicleDimensions& car) {
  const auto box = car.box();
  return box.centreXM + box.lengthM / 2 - car.frontOverhangM;
}

// How far the axle travels from the wheels to lengthM past the bumper, signed with the travel.
double reachM(const processing::VehicleDimensions& car, Travel travel, double pastBumperM) {
  return travel == Travel::kReverse ? -(car.rearOverhangM + pastBumperM)
                                    : car.frontOverhangM + pastBumperM;
}

// A quad from a to b, `width` wide, as two triangles.
void strip(cv::Point2d a, cv::Point2d b, double width, const cv::Vec3f& colour,
           std::vector<GuidelineVertex>& out) {
  const cv::Point2d along = b - a;
  const double length = std::hypot(along.x, along.y);
  if (length <= 0) return;
  const cv::Point2d side = cv::Point2d(-along.y, along.x) * (width / 2 / length);
  const auto vertex = [&](cv::Point2d p) {
    out.push_back({{static_cast<float>(p.x), static_cast<float>(p.y), kAboveGroundM},
                   {colour[0], colour[1], colour[2]}});
  };
  for (const cv::Point2d p : {a - side, a + side, b + side, a - side, b + side, b - side}) {
    vertex(p);
  }
}

std::size_t pathSteps(const processing::VehicleDimensions& car, Travel travel,
                      const GuidelineSettings& settings) {
  return static_cast<std::size_t>(
      std::ceil(std::abs(reachM(car, travel, settings.lengthM)) / kStepM));
}

}  // namespace

cv::Point2d wheelPathPoint(const processing::VehicleDimensions& car, Travel travel,
                           double steeringDeg, int side, double distanceM) {
  const double roadWheel =
      std::clamp(steeringDeg / car.steeringRatio, -kMaxRoadWheelDeg, kMaxRoadWheelDeg) *
      std::numbers::pi / 180;
  const double axleX = travel == Travel::kReverse ? rearAxleX(car) : frontAxleX(car);
  const cv::Point2d wheel(axleX, car.box().centreYM + side * car.wheelTrackM() / 2);
  if (std::abs(std::tan(roadWheel)) < 1e-9) return wheel + cv::Point2d(distanceM, 0);
  // The turn's centre, on the rear axle's line, left of it for a left turn; the vehicle turns
  // about it by the rear axle's distance over its radius.
  const double radius = (frontAxleX(car) - rearAxleX(car)) / std::tan(roadWheel);
  const cv::Point2d centre(rearAxleX(car), car.box().centreYM + radius);
  const double angle = distanceM / radius;
  const cv::Point2d from = wheel - centre;
  return centre + cv::Point2d(from.x * std::cos(angle) - from.y * std::sin(angle),
                              from.x * std::sin(angle) + from.y * std::cos(angle));
}

std::size_t maxGuidelineVertices(const GuidelineSettings& settings) {
  // The longest overhang a vehicle may have (vehicle.*_overhang_m: up to 10 m) bounds the paths.
  processing::VehicleDimensions longest;
  longest.frontOverhangM = longest.rearOverhangM = 10;
  const std::size_t steps = pathSteps(longest, Travel::kForward, settings) + 1;
  return 6 * (2 * steps + settings.markersM.size());
}

void guidelines(const processing::VehicleDimensions& car, const GuidelineSettings& settings,
                Travel travel, double steeringDeg, std::vector<GuidelineVertex>& vertices) {
  vertices.clear();
  const double end = reachM(car, travel, settings.lengthM);
  const std::size_t steps = pathSteps(car, travel, settings);
  for (const int side : {1, -1}) {
    cv::Point2d last = wheelPathPoint(car, travel, steeringDeg, side, 0);
    for (std::size_t k = 1; k <= steps; ++k) {
      const double distance = end * std::min(1.0, static_cast<double>(k) * kStepM / std::abs(end));
      const cv::Point2d next = wheelPathPoint(car, travel, steeringDeg, side, distance);
      strip(last, next, settings.lineWidthM, settings.pathColour, vertices);
      last = next;
    }
  }
  for (std::size_t m = 0; m < settings.markersM.size(); ++m) {
    const double distance = reachM(car, travel, settings.markersM[m]);
    strip(wheelPathPoint(car, travel, steeringDeg, 1, distance),
          wheelPathPoint(car, travel, steeringDeg, -1, distance), settings.lineWidthM,
          settings.markerColours[m], vertices);
  }
}

}  // namespace surroundd::render
