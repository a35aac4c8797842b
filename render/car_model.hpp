#pragma once
// The vehicle drawn in the middle of the surround view: a procedural low-poly car (body, cabin,
// wheels, lights marking front and back), or the car's own glTF model (render/gltf_car.hpp),
// standing on a dark footprint that also covers the ground no camera sees under the vehicle.
// Vehicle frame, x forward.

#include <cstddef>
#include <filesystem>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/vehicle_dimensions.hpp"

namespace surroundd::render {

struct CarVertex {
  float position[3];
  float normal[3];  // outward, for shading
  float colour[3];  // 0..1, as shown; multiplies the part's texture where it has one
  float uv[2];      // in the part's texture: 0,0 its first pixel's corner
};

struct CarModel {
  // Triangles, three vertices each, drawn in parts of one texture each.
  struct Part {
    std::size_t first = 0;  // vertices [first, first + count)
    std::size_t count = 0;
    int texture = -1;  // into `textures`; -1: none
  };
  std::vector<CarVertex> vertices;
  std::vector<Part> parts;
  std::vector<cv::Mat> textures;  // 8-bit RGBA
};

// The car `car` describes (its glTF model, or the procedural one), drawn in its box (car.box()),
// on its footprint, which reaches `marginM` past the body and at least `footprintRadiusM` from the
// vehicle frame's origin in every direction (the open ring of the surround mesh). Throws
// CarModelError for a model file that cannot be used.
CarModel buildCarModel(const processing::VehicleDimensions& car, double footprintRadiusM);

}  // namespace surroundd::render
