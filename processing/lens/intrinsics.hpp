#pragma once
// The numbers that define a lens, as the rig file and the calibration tools hold them, for every
// model (lens/camera_model.hpp turns them into rays and pixels).

#include <array>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace surroundd::processing {

// One enumerator per alternative of processing::Lens (lens/camera_model.hpp), in its order.
enum class LensModel { kPinhole, kFisheye, kOcam };

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

}  // namespace surroundd::processing
