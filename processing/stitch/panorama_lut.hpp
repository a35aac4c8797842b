#pragma once
// The panorama look-up table (paper eq. 1): for every panorama pixel, which camera to sample and
// where, plus a second camera and its weight in the feather band across each seam.
//
// Seams: every camera owns the azimuth sector nearest to its optical axis (seams sit on the
// bisectors between neighbouring cameras' axis azimuths, so for the paper's rig at 45, 135, ...
// degrees). Within featherRad of a seam, where both cameras see the pixel, the neighbour is blended
// in linearly (half and half on the seam). Where the owner does not see a pixel, the camera whose
// sector is nearest and that sees it takes it whole; pixels no camera sees show kUnseenColour and
// are 0 in validMask().
//
// Entries are fixed-point (8 bytes a tap) so that applying the table reads little memory: the
// source position is a pixel index plus 1/128-pixel fractions for bilinear interpolation.

#include <cstdint>
#include <functional>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/bowl_shape.hpp"
#include "processing/panorama_geometry.hpp"
#include "processing/rig.hpp"

namespace surroundd {
class WorkPool;
}

namespace surroundd::processing {

enum class PanoramaProjection {
  kSphere,  // the paper: cameras treated as a pure rotation about the panorama centre
  kBowl,    // rays meet the bowl (ground and wall); that point is projected with each full pose
};

struct PanoramaSettings {
  PanoramaGeometry geometry;
  PanoramaProjection projection = PanoramaProjection::kBowl;
  BowlShape bowl;
  double featherRad = 4.0 * std::numbers::pi / 180;  // full width of the blend band

  bool operator==(const PanoramaSettings&) const = default;
};

// A rig that cannot make a panorama (a camera that sees none of it).
class RigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct LutTap {
  static constexpr int kFractionOne = 128;  // fx, fy unit: 1/128 pixel
  std::uint32_t offset = 0;  // top-left pixel of the 2x2 neighbourhood: row * width + column
  std::uint8_t fx = 0;       // 0..128
  std::uint8_t fy = 0;       // 0..128
  std::uint8_t camera = 0;   // index into the rig, or kUnseen
  std::uint8_t weight = 0;  // blend taps: this camera's share in 1/256 (the primary keeps the rest)

  bool operator==(const LutTap&) const = default;
};
static_assert(sizeof(LutTap) == 8);

// The tap that samples a camera image of `size` at sub-pixel `p` (inside the image).
LutTap encodeTap(const cv::Point2d& p, cv::Size size, std::uint8_t camera);

struct BlendTap {
  std::uint32_t pixel = 0;  // row * width + column
  LutTap tap;

  bool operator==(const BlendTap&) const = default;
};

struct PanoramaLut {
  static constexpr std::uint8_t kUnseen = 255;
  static inline const cv::Vec3b kUnseenColour{0, 0, 0};

  cv::Size size;
  std::vector<cv::Size> cameraSizes;         // the images each camera index refers to
  std::vector<LutTap> taps;                  // one per pixel, row-major
  std::vector<BlendTap> blendTaps;           // sorted by pixel
  std::vector<std::uint32_t> blendRowBegin;  // blend taps of row v: [begin[v], begin[v + 1])

  cv::Mat ownerMap() const;   // CV_8U: the primary camera of each pixel, kUnseen where none
  cv::Mat validMask() const;  // CV_8U: 255 where a camera sees the pixel, else 0
  // The cameras no tap samples (each one's body mask hides all it would show), in rig order.
  std::vector<std::size_t> camerasWithoutTaps() const;

  bool operator==(const PanoramaLut&) const = default;
};

// Maps panorama pixels to camera pixels for one rig: the geometry behind the LUT, also used to
// measure it (seam alignment) without the fixed-point rounding.
class PanoramaProjector {
 public:
  PanoramaProjector(const Rig& rig, const PanoramaSettings& settings);

  // Where camera `camera` sees a panorama (sub-)pixel; nullopt when the point is outside its lens
  // or its image (with room for the 2x2 bilinear neighbourhood), or hidden by the vehicle's body
  // (the camera's body mask, grown by kBodyMargin pixels so that no bilinear tap reaches it).
  std::optional<cv::Point2d> cameraPixel(std::size_t camera,
                                         const cv::Point2d& panoramaPixel) const;
  // The same for a point in the vehicle frame (bowl projection only).
  std::optional<cv::Point2d> cameraPixelOf(std::size_t camera, const cv::Vec3d& point) const;
  // The vehicle-frame point a panorama pixel stands for: on the bowl, or (sphere) one metre from
  // the centre.
  cv::Vec3d surfacePoint(const cv::Point2d& panoramaPixel) const;
  // Azimuth of a camera's optical axis seen from above (its sector's centre), radians.
  double axisAzimuth(std::size_t camera) const { return axisAzimuth_[camera]; }
  std::size_t cameraCount() const { return models_.size(); }
  const PanoramaSettings& settings() const { return settings_; }

 private:
  // Where camera `camera` sees a camera-frame point, as cameraPixel() says.
  std::optional<cv::Point2d> visiblePixel(std::size_t camera, const cv::Vec3d& pointCamera) const;

  PanoramaSettings settings_;
  static constexpr int kBodyMargin = 2;
  std::vector<CameraModel> models_;
  std::vector<Pose> poses_;
  std::vector<cv::Mat> bodyMasks_;  // grown; empty where a camera has none
  std::vector<double> axisAzimuth_;
};

// Fraction of rows done, 0..1, called from the building thread now and then.
using LutProgress = std::function<void(double)>;

// Builds the LUT row-parallel on `pool`. Throws RigError naming a camera that sees none of the
// panorama, and std::invalid_argument for a rig of more than kMaxCameras
// (common/camera_limit.hpp). A camera whose body mask hides all it would show gives the LUT
// nothing and is no error (camerasWithoutTaps() names it): the others make the panorama.
PanoramaLut buildPanoramaLut(const Rig& rig, const PanoramaSettings& settings, WorkPool& pool,
                             const LutProgress& progress = {});

}  // namespace surroundd::processing
