#include "tools/synth/ego_body.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "processing/vehicle_body.hpp"
#include "tools/synth/scene.hpp"

namespace surroundd::synth {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Dark metallic blue: far from the ground's greys and the sky, so a body pixel stitched in as
// ground shows.
const cv::Vec3f kPaint(120, 62, 34);
const cv::Vec3f kHousing(24, 24, 24);
constexpr float kRoofF0 = 0.75f;  // glossy clear coat seen from above: mostly mirror
constexpr float kSideF0 = 0.04f;  // paint: a dielectric's reflectance at normal incidence

// Where a line meets a convex 2D shape: one interval, and the surface where it enters.
struct Span {
  double enter = -kInfinity;
  double exit = kInfinity;
  cv::Vec2d normal;      // outwards, at `enter`
  double curvature = 0;  // 1 / radius there; 0 when flat
};

// The line o + t d against the axis-aligned box |x| <= half[0], |y| <= half[1].
std::optional<Span> boxSpan(const cv::Vec2d& o, const cv::Vec2d& d, const cv::Vec2d& half) {
  Span span;
  for (int i = 0; i < 2; ++i) {
    if (std::abs(d[i]) < 1e-15) {
      if (std::abs(o[i]) > half[i]) return std::nullopt;
      continue;
    }
    const double a = (-half[i] - o[i]) / d[i];
    const double b = (half[i] - o[i]) / d[i];
    if (std::min(a, b) > span.enter) {
      span.enter = std::min(a, b);
      span.normal = i == 0 ? cv::Vec2d(d[0] > 0 ? -1 : 1, 0) : cv::Vec2d(0, d[1] > 0 ? -1 : 1);
    }
    span.exit = std::min(span.exit, std::max(a, b));
  }
  if (span.enter > span.exit) return std::nullopt;
  return span;
}

std::optional<Span> circleSpan(const cv::Vec2d& o, const cv::Vec2d& d, const cv::Vec2d& centre,
                               double radius) {
  const cv::Vec2d p = o - centre;
  const double a = d.dot(d);
  const double c = p.dot(p) - radius * radius;
  if (a < 1e-30) return c <= 0 ? std::optional<Span>(Span{}) : std::nullopt;
  const double b = p.dot(d);
  const double discriminant = b * b - a * c;
  if (discriminant < 0) return std::nullopt;
  const double root = std::sqrt(discriminant);
  Span span;
  span.enter = (-b - root) / a;
  span.exit = (-b + root) / a;
  span.normal = (p + span.enter * d) / radius;
  span.curvature = 1 / radius;
  return span;
}

// A rectangle of half size `half` centred at 0 with corners of `radius`: the union of two crossed
// boxes and four corner circles. The union is convex, so the line meets it from the earliest
// entry to the latest exit among the pieces.
std::optional<Span> roundedRectSpan(const cv::Vec2d& o, const cv::Vec2d& d, const cv::Vec2d& half,
                                    double radius) {
  radius = std::min({radius, half[0], half[1]});
  std::optional<Span> all;
  const auto add = [&](const std::optional<Span>& piece) {
    if (!piece) return;
    if (!all) {
      all = piece;
      return;
    }
    if (piece->enter < all->enter) {
      all->enter = piece->enter;
      all->normal = piece->normal;
      all->curvature = piece->curvature;
    }
    all->exit = std::max(all->exit, piece->exit);
  };
  add(boxSpan(o, d, {half[0], half[1] - radius}));
  add(boxSpan(o, d, {half[0] - radius, half[1]}));
  const cv::Vec2d inner(half[0] - radius, half[1] - radius);
  for (const double sx : {-1.0, 1.0}) {
    for (const double sy : {-1.0, 1.0}) {
      add(circleSpan(o, d, {sx * inner[0], sy * inner[1]}, radius));
    }
  }
  return all;
}

}  // namespace

EgoBody::EgoBody(const daemon::VehicleConfig& vehicle) {
  // A footprint polygon drawn as its bounding box.
  const auto box = vehicle.box();
  centre_ = {box.centreXM, box.centreYM};
  halfSize_ = {box.lengthM / 2, box.widthM / 2, (vehicle.heightM - vehicle.groundClearanceM) / 2};
  centreZ_ = (vehicle.heightM + vehicle.groundClearanceM) / 2;
}

std::optional<BodyHit> EgoBody::intersect(const cv::Vec3d& origin, const cv::Vec3d& direction,
                                          float pixelAngle) const {
  const cv::Vec3d o(origin[0] - centre_[0], origin[1] - centre_[1], origin[2] - centreZ_);
  const cv::Vec3d& d = direction;
  const auto plan =
      roundedRectSpan({o[0], o[1]}, {d[0], d[1]}, {halfSize_[0], halfSize_[1]}, kCornerRadiusM);
  const auto side =
      roundedRectSpan({o[1], o[2]}, {d[1], d[2]}, {halfSize_[1], halfSize_[2]}, kEdgeRadiusM);
  const auto end =
      roundedRectSpan({o[0], o[2]}, {d[0], d[2]}, {halfSize_[0], halfSize_[2]}, kEdgeRadiusM);
  if (!plan || !side || !end) return std::nullopt;
  // The body is the intersection of the three: in from the last entry, out at the first exit.
  const double enter = std::max({plan->enter, side->enter, end->enter});
  const double exit = std::min({plan->exit, side->exit, end->exit});
  const double clearance = processing::VehicleBody::kLensClearanceM;
  if (exit <= clearance || enter >= exit) return std::nullopt;

  BodyHit hit;
  if (enter <= 1e-9) {
    // The camera is on or inside the body and looks into it.
    hit.point = cv::Vec3f(origin + clearance * d);
    hit.normal = cv::Vec3f(-d);
    hit.reflected = hit.normal;
    hit.paint = kHousing;
    return hit;
  }
  cv::Vec3d normal;
  double curvature = 0;
  if (enter == plan->enter) {
    normal = {plan->normal[0], plan->normal[1], 0};
    curvature = plan->curvature;
  } else if (enter == side->enter) {
    normal = {0, side->normal[0], side->normal[1]};
    curvature = side->curvature;
  } else {
    normal = {end->normal[0], 0, end->normal[1]};
    curvature = end->curvature;
  }
  const double cosIncidence = std::clamp(-d.dot(normal), 0.0, 1.0);
  hit.point = cv::Vec3f(origin + enter * d);
  hit.normal = cv::Vec3f(normal);
  hit.reflected = cv::Vec3f(cv::normalize(d - 2 * d.dot(normal) * normal));
  hit.paint = kPaint;
  // The roof's clear coat fades into the flanks' paint over the rounded edge.
  const float roof = static_cast<float>(std::clamp((normal[2] - 0.5) / 0.45, 0.0, 1.0));
  const float f0 = kSideF0 + (kRoofF0 - kSideF0) * roof;
  hit.mirror = f0 + (1 - f0) * static_cast<float>(std::pow(1 - cosIncidence, 5));
  // A curved mirror fans a pixel's rays out by twice the normal's turn across its footprint.
  hit.spread = std::min(0.5f, pixelAngle * static_cast<float>(1 + 2 * enter * curvature));
  return hit;
}

cv::Vec3f EgoBody::shade(const BodyHit& hit, const cv::Vec3f& normalWorld,
                         const cv::Vec3f& reflectedRadiance) {
  return hit.paint * ((1 - hit.mirror) * Scene::sunShading(normalWorld)) +
         reflectedRadiance * hit.mirror;
}

}  // namespace surroundd::synth
