#pragma once
// The views of the surround scene and where their eyes are (DESIGN.md §2.5):
//   top     bird's eye: straight down from above the vehicle, its front up in the picture; the
//           shorter side of the picture spans 2 x topRangeM on the ground.
//   360     the horizontal panorama from the vehicle's centre as two strips, front half above
//           (left side ... front ... right side) and back half below (right ... back ... left),
//           vertical lines straight (a cylinder seen from its axis).
//   orbit   a camera circling the vehicle, looking at it.
//   split   the orbit view on the left half, one camera's own picture on the right.
//   rear    from high above the vehicle's back, looking back and down at the ground behind it:
//           what reversing needs (a still eye; view rules bring it up with gear R).
// Matrices take vehicle-frame points to OpenGL clip space, with rows of the picture top first.

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <opencv2/core.hpp>

namespace surroundd::render {

enum class ViewKind { kTop, kPanorama360, kOrbit, kSplit, kRear };
// Each view by its name, as the config, the control socket and the live page name them.
inline constexpr std::array<std::pair<std::string_view, ViewKind>, 5> kViewNames{{
    {"top", ViewKind::kTop},
    {"360", ViewKind::kPanorama360},
    {"orbit", ViewKind::kOrbit},
    {"split", ViewKind::kSplit},
    {"rear", ViewKind::kRear},
}};

const char* toString(ViewKind view);  // "top", "360", "orbit", "split", "rear"
std::optional<ViewKind> parseViewKind(std::string_view name);
// Every view's name, joined by `separator`: "top, 360, orbit, split, rear".
std::string viewNameList(std::string_view separator);

struct ViewSettings {
  double topRangeM = 8.0;
  double topHeightM = 14.0;    // eye height of the top view
  double orbitRadiusM = 8.0;   // horizontal distance of the orbiting eye from the vehicle
  double orbitHeightM = 4.5;   // its height
  double orbitPeriodS = 20.0;  // one turn, in stream time; 0: the eye stays where it starts
  double orbitStartDeg = 180;  // the eye's azimuth at stream time 0 (180: behind the vehicle)
  double orbitFovDeg = 60.0;   // vertical field of view
  double stripTopDeg = 15.0;   // 360 view: elevation at the top of each strip
  double transitionS = 0.4;    // a switch of view moves there over this much stream time; 0: cuts

  bool operator==(const ViewSettings&) const = default;
};

// Where a perspective view's eye is and what it looks at (top, orbit).
struct ViewPose {
  cv::Vec3d eye;
  cv::Vec3d target;
  cv::Vec3d up;
  double fovyRad = 1;  // vertical field of view
};
ViewPose topViewPose(const ViewSettings& settings, cv::Size viewport);
ViewPose orbitViewPose(const ViewSettings& settings, double timeS);
ViewPose rearViewPose(const ViewSettings& settings);
// The pose of a perspective view (top, orbit, rear) at `timeS`; none for the others.
std::optional<ViewPose> perspectivePose(ViewKind view, const ViewSettings& settings,
                                        cv::Size viewport, double timeS);
// How far a view switch has come at `t` of its time (0..1): eased in and out (smoothstep), so that
// the eye starts and stops gently.
double transitionWeight(double t);
// transitionWeight(t) of the way from `from` to `to`: eye, target, up and field of view each in a
// straight line.
ViewPose poseBetween(const ViewPose& from, const ViewPose& to, double t);
cv::Matx44f viewProjection(const ViewPose& pose, cv::Size viewport);

cv::Matx44f orbitViewProjection(const ViewSettings& settings, cv::Size viewport, double timeS);
// Whether the orbit view's eye moves with stream time.
bool orbitMoves(const ViewSettings& settings);

// The 360 view's strips: elevations (tan) at the top and bottom of a strip of `viewport` / 2
// rows that keeps angles at the horizon undistorted.
cv::Vec2f stripTangents(const ViewSettings& settings, cv::Size viewport);

}  // namespace surroundd::render
