#pragma once
// CPU ray caster for the synthetic cameras and the ground-truth panorama.
//
// Everything that depends only on the rig is computed once per camera (CameraRays): each pixel's
// unit ray in the vehicle frame, its angular footprint, and, because the ground is flat and the
// vehicle only yaws and translates, where along the ray it meets the ground and which mip level
// that needs. Per frame a pixel then costs a 2D rotation, a texture fetch and the occlusion tests
// its 16x16 tile cannot rule out (boxes are culled per tile and frame by a cone test).

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/rig.hpp"
#include "tools/synth/photometrics.hpp"
#include "tools/synth/scene.hpp"
#include "tools/synth/vehicle_path.hpp"

namespace surroundd::synth {

class CameraRays {
 public:
  explicit CameraRays(const processing::CameraCalibration& camera);

  struct Pixel {
    cv::Vec3f direction;   // unit, vehicle frame
    float groundDistance;  // along the ray to z = 0; < 0 when it never gets there
    float groundLod;       // mip level of the ground texture for this pixel
    float pixelAngle;      // radians; < 0 for a pixel outside the lens (rendered black)
  };
  struct Tile {
    cv::Vec3f axis;  // vehicle frame
    float halfAngle = 0, cosHalfAngle = 1, sinHalfAngle = 0;
    bool empty = true;
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

 private:
  cv::Size size_;
  cv::Vec3f position_;
  bool fisheye_ = false;
  std::vector<Pixel> pixels_;
  int tilesX_ = 0;
  std::vector<Tile> tiles_;
  cv::Mat offAxis_;
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
  // without photometrics.
  cv::Mat panorama(const VehiclePose& pose, const cv::Vec3d& centre, cv::Size size) const;

 private:
  void cullBoxes(const VehiclePose& pose, const CameraRays& rays,
                 std::vector<std::uint32_t>& masks);

  const Scene& scene_;
  // Per job, reused across frames so that rendering allocates nothing after the first frame.
  std::vector<std::vector<std::uint32_t>> tileMasks_;
  std::vector<int> firstRow_;
  std::vector<cv::Vec3f> origins_;
};

}  // namespace surroundd::synth
