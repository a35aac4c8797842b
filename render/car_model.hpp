#pragma once
// The vehicle drawn in the middle of the surround view: a procedural low-poly car (body, cabin,
// wheels, lights marking front and back) standing on a dark footprint that also covers the ground
// no camera sees under the vehicle. Vehicle frame, x forward.

#include <vector>

namespace surroundd::render {

struct CarDimensions {
  double lengthM = 4.5;
  double widthM = 1.85;
  double heightM = 1.5;
  double groundClearanceM = 0.15;
  double frontOverhangM = 0.9;  // bumper to axle: where the wheels go
  double rearOverhangM = 1.0;
  double centreXM = 0, centreYM = 0;  // the body's centre in the vehicle frame
  double marginM = 0.3;               // the dark footprint reaches this far past the body

  bool operator==(const CarDimensions&) const = default;
};

struct CarVertex {
  float position[3];
  float normal[3];  // outward, for flat shading
  float colour[3];  // linear 0..1
};

// Triangles, three vertices each. The footprint reaches `marginM` past the body and at least
// `footprintRadiusM` from the vehicle frame's origin in every direction (the open ring of the
// surround mesh).
std::vector<CarVertex> buildCarModel(const CarDimensions& car, double footprintRadiusM);

}  // namespace surroundd::render
