#pragma once
// CPU ray caster for the synthetic cameras and the ground-truth panorama.
//
// Everything that depends only on the rig is computed once per camera (CameraRays): each pixel's
// unit ray in the vehicle frame, its angular footprint, and, because the ground is flat and the
// vehicle only yaws and translates, where along the ray it meets the ground and which mip level
// that needs. Per frame a pixel then costs a 2D rotation, a texture fetch and the occlusion tests
// its 16x16 tile cannot rule out (boxes are culled per tile and frame by a cone test).
//
// The ego vehicle's body, when there is one, is static in the vehicle frame too: which pixels see
// it, where, and where their reflection goes is found once per camera; per frame such a pixel
// costs one scene ray along its reflection.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/rig.hpp"
#include "tools/synth/ego_body.hpp"
#include "tools/synth/photometrics.hpp"
#include "tools/synth/scene.hpp"
#include "tools/synth/vehicle_path.hpp"

namespace surroundd::synth {

class CameraRays {
 public:
  // `body`: the ego vehicle's body, or null for none.
  explicit CameraRays(const processing::CameraCalibration& camera, const EgoBody* body = nullptr);

  struct Pixel {
    cv::Vec3f direction;   // unit, vehicle frame
    float groundDistance;  // along the ray to z = 0; < 0 when it never gets there
    float groundLod;       // mip level of the ground texture for this pixel
    float pixelAngle;      // radians; < 0 for a pixel outside the lens (rendered black)
    std::int32_t body;     // index into bodyHits(); < 0 when the ray misses the body
  };
  // A cone around a bundle of rays that start within `radius` of `apex`; vehicle frame.
  struct Cone {
    cv::Vec3f apex;
    float radius = 0;
    cv::Vec3f axis;
    float halfAngle = 0, cosHalfAngle = 1, sinHalfAngle = 0;
  };
  struct Tile {
    cv::Vec3f axis;  // vehicle frame
    float halfAngle = 0, cosHalfAngle = 1, sinHalfAngle = 0;
    bool empty = true;
    Cone reflections;  // of the tile's pixels that see the body
    bool reflects = false;
  };
  static constexpr int kTileSize = 16;

  cv::Size size() const { return size_; }
  const cv::Vec3f& position() const { return position_; }
  const Pixel* row(int y) const {
    return pixels_.data() + static_cast<std::ptrdiff_t>(y) * size_.width;
  }
  int tilesX() const { return tilesX_; }
  const std::vector<Tile>& tiles() const { return tiles_; }
  // Angle of each pixel's ray off the optical axis (for vignetting), CV_32F; -1 outside the lens.
  const cv::Mat& offAxisAngle() const { return offAxis_; }
  bool fisheye() const { return fisheye_; }
  const std::vector<BodyHit>& bodyHits() const { return bodyHits_; }
  // The true body mask: CV_8U, 255 where the pixel's ray meets the body first.
  cv::Mat bodyMask() const;

 private:
  // The cone of the reflections of the body pixels in [x0, x1) x [y0, y1); false when none.
  bool reflectionCone(int x0, int x1, int y0, int y1, Cone& cone) const;

  cv::Size size_;
  cv::Vec3f position_;
  bool fisheye_ = false;
  std::vector<Pixel> pixels_;
  int tilesX_ = 0;
  std::vector<Tile> tiles_;
  cv::Mat offAxis_;
  std::vector<BodyHit> bodyHits_;
};

// One camera image to produce in a render pass.
struct CameraJob {
  const CameraRays* rays = nullptr;
  const PhotometricCamera* photometrics = nullptr;
  PhotometricCamera::Frame frame;
  cv::Mat* out = nullptr;  // CV_8UC3 of the camera's size, preallocated
};

class SceneRenderer {
 public:
  explicit SceneRenderer(const Scene& scene) : scene_(scene) {}

  // Renders all jobs at one vehicle pose, in parallel over rows (cv::parallel_for_). The result
  // does not depend on the number of threads.
  void render(const VehiclePose& pose, std::vector<CameraJob>& jobs);

  // The true panorama (DESIGN.md §4 convention) seen from `centre` (vehicle frame), 8-bit BGR,
  // without photometrics, and without the ego body: the world a stitcher should show.
  cv::Mat panorama(const VehiclePose& pose, const cv::Vec3d& centre, cv::Size size) const;

 private:
  // Per tile, the boxes its rays may meet (`masks`) and those its body pixels' reflections may
  // meet (`reflectionMasks`, left empty for a camera that does not see the body).
  void cullBoxes(const VehiclePose& pose, const CameraRays& rays, std::vector<std::uint32_t>& masks,
                 std::vector<std::uint32_t>& reflectionMasks);
  // `c`, `s`: cosine and sine of the pose's yaw; `boxMask`: the boxes the reflection may meet.
  cv::Vec3f bodyRadiance(const BodyHit& hit, const VehiclePose& pose, float c, float s,
                         std::uint32_t boxMask) const;

  const Scene& scene_;
  // Per job, reused across frames so that rendering allocates nothing after the first frame.
  std::vector<std::vector<std::uint32_t>> tileMasks_;
  std::vector<std::vector<std::uint32_t>> reflectionMasks_;
  std::vector<int> firstRow_;
  std::vector<cv::Vec3f> origins_;
};

}  // namespace surroundd::synth
