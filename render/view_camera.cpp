#include "render/view_camera.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace surroundd::render {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180;
constexpr float kNearM = 0.1F;
constexpr float kFarM = 200.0F;

cv::Matx44f perspective(double fovyRad, double aspect) {
  const auto f = static_cast<float>(1 / std::tan(fovyRad / 2));
  const auto a = static_cast<float>(aspect);
  // The y row is negated so that row 0 of the framebuffer is the top of the picture.
  return {f / a,
          0,
          0,
          0,  //
          0,
          -f,
          0,
          0,  //
          0,
          0,
          (kFarM + kNearM) / (kNearM - kFarM),
          2 * kFarM * kNearM / (kNearM - kFarM),  //
          0,
          0,
          -1,
          0};
}

cv::Matx44f lookAt(const cv::Vec3f& eye, const cv::Vec3f& target, const cv::Vec3f& up) {
  const cv::Vec3f f = cv::normalize(target - eye);
  const cv::Vec3f s = cv::normalize(f.cross(up));
  const cv::Vec3f u = s.cross(f);
  return {s[0],  s[1],  s[2],  -s.dot(eye),  //
          u[0],  u[1],  u[2],  -u.dot(eye),  //
          -f[0], -f[1], -f[2], f.dot(eye),   //
          0,     0,     0,     1};
}

double aspectOf(cv::Size viewport) { return static_cast<double>(viewport.width) / viewport.height; }

}  // namespace

const char* toString(ViewKind view) {
  const auto* named =
      std::ranges::find(kViewNames, view, &std::pair<std::string_view, ViewKind>::second);
  return named == kViewNames.end() ? "?" : named->first.data();
}

std::optional<ViewKind> parseViewKind(std::string_view name) {
  const auto* named =
      std::ranges::find(kViewNames, name, &std::pair<std::string_view, ViewKind>::first);
  return named == kViewNames.end() ? std::nullopt : std::optional(named->second);
}

std::string viewNameList(std::string_view separator) {
  std::string list;
  for (const auto& [name, view] : kViewNames) {
    if (!list.empty()) list += separator;
    list += name;
  }
  return list;
}

ViewPose topViewPose(const ViewSettings& settings, cv::Size viewport) {
  const double aspect = aspectOf(viewport);
  // Half the picture's height on the ground: the range itself, or more where the picture is
  // taller than wide and its width is the shorter side.
  const double halfHeightM = aspect >= 1 ? settings.topRangeM : settings.topRangeM / aspect;
  return {{0, 0, settings.topHeightM},
          {0, 0, 0},
          {1, 0, 0},
          2 * std::atan(halfHeightM / settings.topHeightM)};
}

ViewPose orbitViewPose(const ViewSettings& settings, double timeS) {
  const double turns = orbitMoves(settings) ? timeS / settings.orbitPeriodS : 0;
  const double angle = settings.orbitStartDeg * kDegToRad + 2 * std::numbers::pi * turns;
  return {{settings.orbitRadiusM * std::cos(angle), settings.orbitRadiusM * std::sin(angle),
           settings.orbitHeightM},
          {0, 0, 0.5},
          {0, 0, 1},
          settings.orbitFovDeg * kDegToRad};
}

ViewPose rearViewPose(const ViewSettings& settings) {
  // High above the car's back, looking about 57 degrees down: the rear half of the car at the
  // bottom of the picture, and the ground from just past its bumper (the roof hides the first
  // 0.3 m of a car's) to nearly 2 orbit radii behind it.
  return {{-0.15 * settings.orbitRadiusM, 0, 1.5 * settings.orbitHeightM},
          {-0.7 * settings.orbitRadiusM, 0, 0},
          {0, 0, 1},
          settings.orbitFovDeg * kDegToRad};
}

std::optional<ViewPose> perspectivePose(ViewKind view, const ViewSettings& settings,
                                        cv::Size viewport, double timeS) {
  switch (view) {
    case ViewKind::kTop:
      return topViewPose(settings, viewport);
    case ViewKind::kOrbit:
      return orbitViewPose(settings, timeS);
    case ViewKind::kRear:
      return rearViewPose(settings);
    case ViewKind::kPanorama360:
    case ViewKind::kSplit:
      break;
  }
  return std::nullopt;
}

double transitionWeight(double t) {
  const double s = std::clamp(t, 0.0, 1.0);
  return s * s * (3 - 2 * s);
}

ViewPose poseBetween(const ViewPose& from, const ViewPose& to, double t) {
  const double eased = transitionWeight(t);
  const auto lerp = [eased](const auto& a, const auto& b) { return a + (b - a) * eased; };
  return {lerp(from.eye, to.eye), lerp(from.target, to.target), cv::normalize(lerp(from.up, to.up)),
          lerp(from.fovyRad, to.fovyRad)};
}

cv::Matx44f viewProjection(const ViewPose& pose, cv::Size viewport) {
  const auto vec = [](const cv::Vec3d& v) { return cv::Vec3f(v); };
  return perspective(pose.fovyRad, aspectOf(viewport)) *
         lookAt(vec(pose.eye), vec(pose.target), vec(pose.up));
}

cv::Matx44f orbitViewProjection(const ViewSettings& settings, cv::Size viewport, double timeS) {
  return viewProjection(orbitViewPose(settings, timeS), viewport);
}

bool orbitMoves(const ViewSettings& settings) { return settings.orbitPeriodS > 0; }

cv::Vec2f stripTangents(const ViewSettings& settings, cv::Size viewport) {
  // A strip is half a turn wide; at the horizon a radian takes as many rows as columns.
  const double pixelsPerRadian = viewport.width / std::numbers::pi;
  const double top = std::tan(settings.stripTopDeg * kDegToRad);
  const double bottom = top - (viewport.height / 2.0) / pixelsPerRadian;
  return {static_cast<float>(top), static_cast<float>(bottom)};
}

}  // namespace surroundd::render
