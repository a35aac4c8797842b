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

  bool operator==(const CarDimensions&) const = default;
};

struct CarVertex {
  float position[3];
  float normal[3];  // outward, for flat shading
  float colour[3];  // linear 0..1
};

// Triangles, three vertices each. The footprint reaches at least `footprintRadiusM` from the
// centre in every direction (the open ring of the surround mesh).
std::vector<CarVertex> buildCarModel(const CarDimensions& car, double footprintRadiusM);

}  // namespace surroundd::render
