#pragma once
// The ego vehicle's body as the synthetic cameras see it: the generator's own model, deliberately
// more detailed than the prism the stitcher masks with (processing::VehicleBody), so that comparing
// the stitcher's computed masks with the masks rendered here measures something.
//
// Shape: the vehicle's box (length, width, ground clearance to roof, centred on x_m, y_m) with its
// vertical corners rounded (kCornerRadiusM) and the edges of roof and sills rounded
// (kEdgeRadiusM). It is the intersection of three extrusions, each a rounded rectangle: the plan
// view extruded vertically, the side profile extruded along x and the end profile along y; so it is
// convex, and a ray meets it in one interval. A footprint polygon is drawn as its bounding box.
//
// Paint: a body colour lit by the scene's sun, plus a mirror reflection of the scene weighted by a
// Schlick Fresnel term; the roof is mostly mirror (a glossy roof shows the sky and what stands
// around the car, which is what a stitcher must not take for ground), the flanks mostly paint.

#include <optional>

#include <opencv2/core.hpp>

#include "daemon/config/vehicle_yaml.hpp"

namespace surroundd::synth {

// Where a camera pixel's ray meets the body; everything in the vehicle frame, which the body does
// not move in, so it is computed once per pixel.
struct BodyHit {
  cv::Vec3f point;      // metres
  cv::Vec3f normal;     // unit, outwards
  cv::Vec3f reflected;  // unit: the ray mirrored about the normal
  cv::Vec3f paint;      // BGR albedo, 0..255
  float mirror = 0;     // weight of the reflected radiance, 0..1
  float spread = 0;     // angular size of the reflected pixel, radians (curved edges widen it)
};

class EgoBody {
 public:
  static constexpr double kCornerRadiusM = 0.15;  // vertical corners, plan view
  static constexpr double kEdgeRadiusM = 0.04;    // roof and sill edges

  explicit EgoBody(const daemon::VehicleConfig& vehicle);

  // The body along the ray origin + t * direction (unit), seen from a camera at `origin` with
  // pixels of `pixelAngle` radians. A camera sits on the body's surface: like
  // processing::VehicleBody, the ray sees the body where it is inside it further than
  // VehicleBody::kLensClearanceM from the origin; a ray that starts inside it and runs on inside
  // sees the camera's dark housing.
  std::optional<BodyHit> intersect(const cv::Vec3d& origin, const cv::Vec3d& direction,
                                   float pixelAngle) const;

  // The colour of a hit: `normalWorld` is its normal turned into the world (the sun is fixed
  // there), `reflectedRadiance` the scene along the reflected ray.
  static cv::Vec3f shade(const BodyHit& hit, const cv::Vec3f& normalWorld,
                         const cv::Vec3f& reflectedRadiance);

 private:
  cv::Vec2d centre_;    // plan view, vehicle frame
  cv::Vec3d halfSize_;  // half length, half width, half height (clearance to roof)
  double centreZ_ = 0;  // halfway between clearance and roof
};

}  // namespace surroundd::synth
