#pragma once
// The car's own 3D model from a glTF 2.0 file (.glb or .gltf, read by tinygltf): the triangles of
// its default scene, each node's transform applied, with their materials' base colours and
// base-colour textures. glTF's axes (+Y up, the model's front towards +Z) become the vehicle
// frame's (x forward, y left, z up), and the model's bounding box is scaled on each axis to the
// vehicle's box: `car`'s length, width and height, standing on the ground at its centre.
//
// Error policy: CarModelError naming the file and what is wrong with it (unreadable, not glTF, no
// triangles, an accessor or texture it cannot use); nothing is partly loaded.

#include <filesystem>
#include <stdexcept>

#include "render/car_model.hpp"

namespace surroundd::render {

class CarModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The model's parts, without the footprint.
CarModel loadGltfCar(const std::filesystem::path& file, const processing::VehicleDimensions& car);

}  // namespace surroundd::render
