// The render meshes: UVs are the panorama coordinates of each vertex's direction from the centre,
// the bowl is one closed sheet on the stitcher's own surface, and bad settings are refused.

#include "processing/surround_mesh.hpp"

#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include <gtest/gtest.h>

namespace surroundd::processing {
namespace {

constexpr double kPi = std::numbers::pi;

PanoramaGeometry paperPanorama() {
  PanoramaGeometry p;
  p.size = {2048, 1024};
  p.centre = {0, 0, 1.9};
  return p;
}

MeshSettings settingsFor(MeshModel model) {
  MeshSettings s;
  s.model = model;
  s.rings = 40;
  s.segments = 96;
  return s;
}

cv::Vec3d positionOf(const MeshVertex& v) { return {v.position[0], v.position[1], v.position[2]}; }

class EveryModel : public testing::TestWithParam<MeshModel> {};

TEST_P(EveryModel, UvMapsBackToEachVertexDirection) {
  const PanoramaGeometry panorama = paperPanorama();
  const SurroundMesh mesh = buildSurroundMesh(settingsFor(GetParam()), panorama);
  ASSERT_EQ(mesh.vertices.size(), 41u * 97u);
  const double span = panorama.elevationTopRad - panorama.elevationBottomRad;
  for (const MeshVertex& vertex : mesh.vertices) {
    const double azimuth = -kPi + 2 * kPi * vertex.uv[0];
    const double elevation = panorama.elevationTopRad - span * vertex.uv[1];
    const cv::Vec3d fromUv(std::cos(elevation) * std::cos(azimuth),
                           std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    const cv::Vec3d actual = cv::normalize(positionOf(vertex) - panorama.centre);
    ASSERT_LT(cv::norm(fromUv - actual), 1e-5)
        << "vertex at " << positionOf(vertex) << " uv " << vertex.uv[0] << ", " << vertex.uv[1];
    EXPECT_GE(vertex.uv[1], -1e-6F);
    EXPECT_LE(vertex.uv[1], 1 + 1e-6F);
  }
}

TEST_P(EveryModel, CoversThePanoramaFromBottomToTopWithNoTriangleAcrossTheSeam) {
  const PanoramaGeometry panorama = paperPanorama();
  const SurroundMesh mesh = buildSurroundMesh(settingsFor(GetParam()), panorama);
  EXPECT_NEAR(mesh.vertices.front().uv[1], 1.0, 1e-6);  // first ring: the bottom elevation
  // Last ring: the top elevation, or for the flat disk its rim on the ground, 9 m out.
  const double rimElevation =
      GetParam() == MeshModel::kFlat ? std::atan2(-1.9, 9.0) : panorama.elevationTopRad;
  EXPECT_NEAR(mesh.vertices.back().uv[1],
              (panorama.elevationTopRad - rimElevation) /
                  (panorama.elevationTopRad - panorama.elevationBottomRad),
              1e-6);
  ASSERT_EQ(mesh.indices.size() % 3, 0u);
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    float lo = 1, hi = 0;
    for (std::size_t k = 0; k < 3; ++k) {
      const float u = mesh.vertices[mesh.indices[t + k]].uv[0];
      lo = std::min(lo, u);
      hi = std::max(hi, u);
    }
    ASSERT_LE(hi - lo, 1.0F / 96 + 1e-6F) << "triangle " << t / 3 << " wraps around the seam";
  }
}

INSTANTIATE_TEST_SUITE_P(SurroundMesh, EveryModel,
                         testing::Values(MeshModel::kFlat, MeshModel::kSphere360, MeshModel::kBowl),
                         [](const testing::TestParamInfo<MeshModel>& param) {
                           switch (param.param) {
                             case MeshModel::kFlat:
                               return "flat";
                             case MeshModel::kSphere360:
                               return "sphere360";
                             case MeshModel::kBowl:
                               return "bowl";
                           }
                           return "unknown";
                         });

TEST(SurroundMesh, BowlLiesOnTheStitchersSurfaceWithItsFloorOnTheGround) {
  const MeshSettings settings = settingsFor(MeshModel::kBowl);
  const PanoramaGeometry panorama = paperPanorama();
  const SurroundMesh mesh = buildSurroundMesh(settings, panorama);
  int floor = 0, wall = 0, cylinder = 0;
  for (const MeshVertex& vertex : mesh.vertices) {
    const cv::Vec3d p = positionOf(vertex);
    const double r = std::hypot(p[0], p[1]);
    if (r < settings.bowl.rimRadiusM - 1e-4) {
      // The point the bowl projection of the panorama puts in this direction is this vertex.
      const auto hit = settings.bowl.intersect(panorama.centre, p - panorama.centre);
      ASSERT_TRUE(hit.has_value());
      EXPECT_LT(cv::norm(*hit - p), 1e-4) << "vertex " << p;
      EXPECT_NEAR(p[2], settings.bowl.height(r), 1e-5);
      (r <= settings.bowl.floorRadiusM ? floor : wall) += 1;
    } else {
      EXPECT_NEAR(r, settings.bowl.rimRadiusM, 1e-4);
      EXPECT_GE(p[2], settings.bowl.rimHeightM - 1e-5);
      ++cylinder;
    }
  }
  EXPECT_GT(floor, 0);
  EXPECT_GT(wall, 0);
  EXPECT_GT(cylinder, 0);
  // The open ring under the vehicle is where the ground is steeper than the bottom elevation.
  EXPECT_NEAR(mesh.innerRadiusM, 1.9 / std::tan(kPi / 3), 1e-6);
}

// Vertices welded by position (the seam column is duplicated for its UVs).
std::vector<std::uint32_t> weldedIds(const SurroundMesh& mesh) {
  std::map<std::tuple<long, long, long>, std::uint32_t> ids;
  std::vector<std::uint32_t> welded;
  for (const MeshVertex& v : mesh.vertices) {
    const auto key =
        std::make_tuple(std::lround(v.position[0] * 1e4), std::lround(v.position[1] * 1e4),
                        std::lround(v.position[2] * 1e4));
    welded.push_back(ids.emplace(key, static_cast<std::uint32_t>(ids.size())).first->second);
  }
  return welded;
}

TEST(SurroundMesh, BowlIsOneSheetWithoutCracksOpenOnlyUnderTheCarAndAtTheTop) {
  const MeshSettings settings = settingsFor(MeshModel::kBowl);
  const SurroundMesh mesh = buildSurroundMesh(settings, paperPanorama());
  const std::vector<std::uint32_t> id = weldedIds(mesh);
  // Directed edges: in a crack-free, consistently wound sheet every inner edge is used once in
  // each direction; the border edges once.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t a = id[mesh.indices[t + k]];
      const std::uint32_t b = id[mesh.indices[t + (k + 1) % 3]];
      ASSERT_NE(a, b) << "degenerate triangle " << t / 3;
      ++directed[{a, b}];
    }
  }
  int inner = 0, border = 0;
  for (const auto& [edge, count] : directed) {
    ASSERT_EQ(count, 1) << "edge used twice in the same direction";
    if (directed.contains({edge.second, edge.first})) {
      ++inner;
    } else {
      ++border;
    }
  }
  // Two border loops of `segments` edges: the ring under the car and the top of the wall.
  EXPECT_EQ(border, 2 * settings.segments);
  EXPECT_EQ(inner, 6 * settings.rings * settings.segments - 2 * settings.segments);
}

TEST(SurroundMesh, RefusesSettingsItCannotMeet) {
  MeshSettings settings = settingsFor(MeshModel::kFlat);
  settings.flatRadiusM = 0.5;  // inside the ground hidden under the car
  EXPECT_THROW(buildSurroundMesh(settings, paperPanorama()), std::invalid_argument);
  settings = settingsFor(MeshModel::kBowl);
  settings.segments = 4;
  EXPECT_THROW(buildSurroundMesh(settings, paperPanorama()), std::invalid_argument);
  PanoramaGeometry lookingUp = paperPanorama();
  lookingUp.elevationBottomRad = 0.1;
  EXPECT_THROW(buildSurroundMesh(settingsFor(MeshModel::kBowl), lookingUp), std::invalid_argument);
}

}  // namespace
}  // namespace surroundd::processing
