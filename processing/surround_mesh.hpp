#pragma once
// The surfaces the panorama is textured onto (DESIGN.md §2.4): a flat disk on the ground, the
// 360-horizontal cropped sphere around the projection centre, and the bowl (BowlShape: the same
// surface the bowl projection of the panorama assumes).
//
// Each mesh is a grid of rings (along the surface's profile, inside out) by segments (azimuth
// -pi..pi, the first and last column duplicated on the ±pi seam so that no triangle wraps). A
// vertex's UV is the panorama coordinate of its direction seen from the panorama's centre:
// u = (azimuth + pi) / 2pi, v = (top - elevation) / (top - bottom). The meshes cover exactly what
// the panorama covers: the ground ring steeper than the panorama's bottom elevation (under the
// vehicle) is left open, and the car model covers it.

#include <cstdint>
#include <vector>

#include "processing/bowl_shape.hpp"
#include "processing/panorama_geometry.hpp"

namespace surroundd::processing {

enum class MeshModel { kFlat, kSphere360, kBowl };

struct MeshSettings {
  MeshModel model = MeshModel::kBowl;
  double flatRadiusM = 9.0;
  double sphereRadiusM = 10.0;
  BowlShape bowl;
  int rings = 48;      // >= 2
  int segments = 128;  // >= 8
};

struct MeshVertex {
  float position[3];  // vehicle frame, metres
  float uv[2];
};

struct SurroundMesh {
  std::vector<MeshVertex> vertices;
  std::vector<std::uint32_t> indices;  // triangles, all wound the same way
  double innerRadiusM = 0;             // radius of the open ring under the vehicle (0: none)
};

// Throws std::invalid_argument for settings no mesh can be made from (too few rings or segments,
// a panorama whose bottom elevation does not look down, a centre not above the ground).
SurroundMesh buildSurroundMesh(const MeshSettings& settings, const PanoramaGeometry& panorama);

}  // namespace surroundd::processing
