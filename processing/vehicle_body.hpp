#pragma once
// The ego vehicle as its own cameras see it, and the pixels of each camera that see it.
//
// On a real car every camera sees part of the car itself: bumpers, doors, mirrors, a roof whose
// glossy paint mirrors the ground. Those pixels are not the ground the panorama stands for, so the
// stitcher must not sample them where another camera sees that ground, and colour statistics must
// leave them out. The body is a vertical prism over the vehicle's footprint (a polygon in the
// vehicle frame), from the ground clearance to the roof: coarse, but a camera bolted onto the body
// sees mostly its flanks and its roof edge, which a prism gets right.

#include <optional>
#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/rig.hpp"

namespace surroundd {
class WorkPool;
}

namespace surroundd::processing {

struct VehicleBody {
  std::vector<cv::Point2d> footprint;  // vehicle frame (x forward, y left), metres; >= 3 corners
  double clearanceM = 0.15;            // the underside, above the ground
  double heightM = 1.5;                // the roof, above the ground

  // A ray sees the body when it is inside the prism anywhere further than kLensClearanceM from
  // its origin: a camera mounted on (or a little inside) the body's surface sees out through the
  // face it sits on, and into the body everywhere else.
  static constexpr double kLensClearanceM = 0.1;
  bool blocks(const cv::Vec3d& origin, const cv::Vec3d& direction) const;
};

// A box body: length along x, width along y, centred on `centre` (vehicle frame, metres).
VehicleBody boxBody(double lengthM, double widthM, double heightM, double clearanceM,
                    const cv::Point2d& centre = {});

// The pixels of `camera` whose rays see `body` (CV_8U of the lens's image size, 255 = body),
// row-parallel on `pool`.
cv::Mat computeBodyMask(const VehicleBody& body, const CameraCalibration& camera, WorkPool& pool);

// Intersection over union of two body masks (non-zero = body); 1 when both are empty.
double maskIoU(const cv::Mat& a, const cv::Mat& b);

}  // namespace surroundd::processing
