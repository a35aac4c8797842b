#pragma once
// Lens models: where a 3D point in the camera frame lands in the image, and back.
//
// Camera frame is OpenCV's: x right, y down, z forward (optical axis). Both models match OpenCV
// exactly where OpenCV defines them (cv::projectPoints for pinhole + radial-tangential,
// cv::fisheye::projectPoints for Kannala-Brandt), so calibrations from calib3d drop in unchanged.
// The fisheye model is extended past 90 degrees by taking theta = atan2(|xy|, z), which is what a
// 190-degree lens needs and agrees with OpenCV for z > 0. The OCamCalib model (Scaramuzza's, which
// many automotive kits ship) follows its world2cam / cam2world exactly for z > 0 and is extended
// past 90 degrees the same way.

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

namespace surroundd::processing {

// A new model is one more name here and in kLensModels; each switch over the models below (no
// default: the compiler names one that misses it) says what it is, and lensKey() what defines it.
enum class LensModel { kPinhole, kFisheye, kOcam };
inline constexpr std::array kLensModels{LensModel::kPinhole, LensModel::kFisheye, LensModel::kOcam};

// The model's name as the rig file and the tools' options spell it (lens.model, --lens).
constexpr std::string_view lensModelName(LensModel model) {
  switch (model) {
    case LensModel::kPinhole:
      return "pinhole";
    case LensModel::kFisheye:
      return "fisheye";
    case LensModel::kOcam:
      return "ocam";
  }
  return "?";
}

// The model named `name` (lensModelName()'s spelling), or none.
constexpr std::optional<LensModel> lensModelNamed(std::string_view name) {
  for (const LensModel model : kLensModels) {
    if (lensModelName(model) == name) return model;
  }
  return std::nullopt;
}

// Whether the model is a wide-angle lens's: its field may reach past 90 degrees, ends at
// maxFieldAngleRad, and shows as an image circle in the picture. A pinhole lens sees only what is
// in front of it, and its field is its picture's.
constexpr bool isWideAngle(LensModel model) {
  switch (model) {
    case LensModel::kPinhole:
      return false;
    case LensModel::kFisheye:
    case LensModel::kOcam:
      return true;
  }
  return false;
}

struct Intrinsics {
  LensModel model = LensModel::kPinhole;
  cv::Size imageSize;     // pixels
  double fx = 0, fy = 0;  // focal lengths, pixels (pinhole, fisheye; ocam leaves them unused)
  double cx = 0, cy = 0;  // principal point, pixels (pixel centres at integer coordinates)
  // Pinhole: k1, k2, p1, p2, k3 (OpenCV order). Fisheye: k1, k2, k3, k4; the fifth is unused (0).
  std::array<double, 5> distortion{};
  // Fisheye and ocam: rays further than this from the optical axis are outside the lens (radians).
  // Pinhole: rays must have z > 0 and stay inside the monotonic part of the distortion.
  double maxFieldAngleRad = 0;
  // OCamCalib only. `cx`, `cy` hold the distortion centre (xc, yc) as column, row; [c d; e 1] is
  // the affine matrix from the sensor plane to pixels. `worldToImage` holds the "invpol"
  // coefficients p0, p1, ... of rho(theta) = sum p_i theta^i, theta = atan(-1 / r) the ray's
  // elevation below the sensor plane (-pi/2 on the axis; see ../shared/data/README.md).
  // `imageToWorld` holds the optional "pol" coefficients a0, a1, ... of OCamCalib's image-to-world
  // polynomial z(rho) = sum a_i rho^i (a0 < 0); empty: unproject by inverting `worldToImage`
  // numerically.
  struct Ocam {
    double c = 1, d = 0, e = 0;
    std::vector<double> worldToImage;
    std::vector<double> imageToWorld;
    bool operator==(const Ocam&) const = default;
  } ocam;

  bool operator==(const Intrinsics&) const = default;
};

// Every number that defines the lens, exactly (hexadecimal floats), one line: what anything built
// from the lens (the panorama's LUT cache) keys on. It names each member of Intrinsics, so a
// member added there does not compile until it is added here too.
std::string lensKey(const Intrinsics& intrinsics);

class CameraModel {
 public:
  explicit CameraModel(const Intrinsics& intrinsics);

  // Pixel of a camera-frame point; nullopt when the point is behind the lens or outside its field.
  // The pixel may still lie outside the image; use inImage() for that.
  std::optional<cv::Point2d> project(const cv::Vec3d& pointCamera) const;

  // Unit ray in the camera frame through a pixel; nullopt when the pixel is outside the lens's
  // valid image circle (fisheye) or the distortion cannot be inverted there.
  std::optional<cv::Vec3d> unproject(const cv::Point2d& pixel) const;

  bool inImage(const cv::Point2d& pixel) const;
  const Intrinsics& intrinsics() const { return intrinsics_; }

  // Pixels per radian of ray angle at the optical axis, along the image's x and y: fx, fy for
  // pinhole and fisheye; for ocam the slope of rho(theta) there, through the affine matrix. For
  // thresholds and sampling densities (ocam has no focal length of its own).
  cv::Vec2d axisFocalPx() const;

  // Where the radial polynomial stops increasing inside the field the lens asks for: beyond it
  // two rays would share a pixel, so the lens is taken to end there and the field is cut.
  struct FieldCut {
    double atRad;     // off-axis angle where the polynomial turns
    double askedRad;  // the field asked for (pinhole: the widest taken at all, about 84 degrees)
    bool inImage;     // the image reaches past the cut: part of the picture is lost
  };
  std::optional<FieldCut> fieldCut() const { return fieldCut_; }

 private:
  std::optional<cv::Vec3d> unprojectOcam(const cv::Point2d& pixel) const;
  // Pinhole, fisheye: the distorted normalized image point; ocam: the sensor-plane point in pixels
  // before the affine matrix.
  cv::Point2d sensorPoint(const cv::Point2d& pixel) const;
  double sensorRadius(const cv::Point2d& pixel) const;

  Intrinsics intrinsics_;
  // At the edge of the valid field: pinhole, the undistorted normalized radius; fisheye, the
  // distorted one; ocam, rho in pixels (before the affine matrix).
  double maxRadius_ = 0;
  double axisRho_ = 0;  // ocam: rho on the axis, which a fitted polynomial leaves slightly off 0
  std::optional<FieldCut> fieldCut_;
};

}  // namespace surroundd::processing
