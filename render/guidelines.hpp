#pragma once
// Parking guidelines: where the vehicle will go at its steering angle, drawn on the ground of the
// surround views — the paths of the rear wheels when reversing (of the front wheels going
// forward) and distance markers across them past the bumper.
//
// A bicycle model with Ackermann steering: the road wheels turn by the steering-wheel angle over
// the steering ratio (at most 45 degrees); the vehicle then turns about one centre on the rear
// axle's line, wheelbase / tan(road-wheel angle) to the side, and every point of it — each wheel
// — runs on a circle about that centre. Positive angles turn left, as VehicleSignals has them.

#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "render/car_model.hpp"

namespace surroundd::render {

enum class Travel { kForward, kReverse };

struct GuidelineSettings {
  double lengthM = 3.0;                         // how far past the bumper the paths reach
  std::vector<double> markersM{0.5, 1.0, 2.0};  // distance markers past the bumper
  // RGB, 0..1, whole eighth bits (as "#rrggbb" gives them): amber paths; red, amber and green
  // markers.
  cv::Vec3f pathColour{1.0F, 209 / 255.0F, 0.0F};
  std::vector<cv::Vec3f> markerColours{{1.0F, 48 / 255.0F, 32 / 255.0F},
                                       {1.0F, 209 / 255.0F, 0.0F},
                                       {48 / 255.0F, 209 / 255.0F, 64 / 255.0F}};  // per marker
  double lineWidthM = 0.08;

  bool operator==(const GuidelineSettings&) const = default;
};

// Where a wheel is after the vehicle has gone `distanceM` (negative: backwards) at a steering-wheel
// angle of `steeringDeg`, on the ground in the vehicle frame: `side` +1 the left wheel, -1 the
// right, of the rear axle when reversing and of the front axle going forward.
cv::Point2d wheelPathPoint(const processing::VehicleDimensions& car, Travel travel,
                           double steeringDeg, int side, double distanceM);

// One vertex of the guidelines' triangles: on the ground (a little above it, so that it is drawn
// over the floor), in the vehicle frame, with its colour.
struct GuidelineVertex {
  float position[3];
  float colour[3];
};

// The most vertices guidelines() makes for `settings`: what a buffer is sized to once.
std::size_t maxGuidelineVertices(const GuidelineSettings& settings);

// The guidelines' triangles into `vertices` (cleared first; never above its capacity when that is
// maxGuidelineVertices(settings)): the two wheel paths, from the wheels to lengthM past the
// bumper, and a marker across them at each of markersM past the bumper.
void guidelines(const processing::VehicleDimensions& car, const GuidelineSettings& settings,
                Travel travel, double steeringDeg, std::vector<GuidelineVertex>& vertices);

}  // namespace surroundd::render
