#pragma once
// What the lens models share: a radial mapping (distorted radius against the undistorted one, or
// against the angle off the axis), where it stops increasing, and its inverse.

#include <algorithm>
#include <cmath>

namespace surroundd::processing {

struct Radial {
  double value;       // distorted radius
  double derivative;  // d value / d radius
};

// Largest radius (pinhole: normalized image radius; fisheye, ocam: field angle) up to `limit` over
// which the radial mapping keeps increasing: beyond it two rays would share a pixel, so the lens
// is treated as ending there.
template <typename RadialFn>
double monotonicLimit(RadialFn radial, double limit) {
  constexpr int kSteps = 4000;
  for (int i = 1; i <= kSteps; ++i) {
    const double r = limit * i / kSteps;
    if (radial(r).derivative <= 0) return limit * (i - 1) / kSteps;
  }
  return limit;
}

// The off-axis angle in [0, limit] where an increasing radial mapping reaches `target`: Newton,
// with a bisection step whenever Newton would leave the bracket, so a polynomial that is nearly
// flat somewhere (OCamCalib fits often are near their edge) still converges.
template <typename RadialFn>
double invertRadial(RadialFn radial, double target, double guess, double limit) {
  double low = 0;
  double high = limit;
  double x = std::clamp(guess, low, high);
  for (int i = 0; i < 100; ++i) {
    const Radial f = radial(x);
    const double error = f.value - target;
    if (error == 0) break;
    (error < 0 ? low : high) = x;
    double next = x - error / f.derivative;
    if (!(next > low && next < high)) next = (low + high) / 2;
    const bool converged = std::abs(next - x) < 1e-15;
    x = next;
    if (converged) break;
  }
  return x;
}

// How far a lens's field reaches: the angle off the axis it was asked for, the angle where its
// polynomial lets it end (no further than asked), and the distorted radius there, in the units
// of the lens's sensorRadius().
struct LensField {
  double askedRad = 0;
  double fieldRad = 0;
  double edgeRadius = 0;
};

}  // namespace surroundd::processing
