#pragma once
// The ego vehicle's measurements, as one `vehicle:` block gives them
// (daemon/config/vehicle_yaml.hpp): one type for every part that needs them — the body the cameras
// see (body()), the car model and the guidelines drawn in its box (box(), render/), the views'
// default sizes and the generator's ego car. Vehicle frame: x forward, y left, metres.

#include <array>
#include <filesystem>
#include <vector>

#include "processing/vehicle_body.hpp"

namespace surroundd::processing {

struct VehicleDimensions {
  double lengthM = 4.5;  // bumper to bumper
  double widthM = 1.85;  // without mirrors
  double heightM = 1.5;
  double groundClearanceM = 0.15;
  double frontOverhangM = 0.9;  // bumper to axle: where the wheels go
  double rearOverhangM = 1.0;
  double xM = 0.0, yM = 0.0;                     // the length x width box's centre
  std::vector<std::array<double, 2>> footprint;  // a polygon instead of the box; empty: the box
  double marginM = 0.3;       // the dark ground patch drawn around the model reaches this far out
  double trackM = 0;          // between the wheels' centres; 0: width less 0.25 m (wheelTrackM())
  double steeringRatio = 15;  // steering-wheel angle over road-wheel angle
  // A glTF 2.0 file (.glb, .gltf) drawn in the box instead of the procedural car; empty: none.
  std::filesystem::path model;

  // The body as the cameras see it: a prism over the footprint (or the box).
  VehicleBody body() const;

  // The box the car model and the guidelines are drawn in: the footprint's bounding box (the box
  // itself when there is no footprint).
  struct Box {
    double lengthM = 0, widthM = 0;
    double centreXM = 0, centreYM = 0;
  };
  Box box() const;
  // Between the wheels' centres: trackM, or the box's width less 0.25 m (at least 0.1 m).
  double wheelTrackM() const;
  // The furthest the body reaches from the vehicle frame's origin.
  double reachM() const;

  bool operator==(const VehicleDimensions&) const = default;
};

}  // namespace surroundd::processing
