#include "processing/colour/colour_balance.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace surroundd::processing {
namespace {

// How strongly the average is held (the fit's anchor row), against pair weights of some tens of
// blocks: enough that the anchor holds to a thousandth, not so much that the system is ill
// conditioned.
constexpr double kAnchorWeight = 1e3;

// The index of the camera named `name`; none for no name.
std::optional<std::size_t> cameraNamed(const std::vector<std::string>& names,
                                       std::string_view name) {
  if (name.empty()) return std::nullopt;
  const auto found = std::ranges::find(names, name);
  if (found == names.end()) {
    throw std::invalid_argument(
        fmt::format("the balance's reference: no camera is named '{}'", name));
  }
  return static_cast<std::size_t>(found - names.begin());
}

}  // namespace

ColourBalance::ColourBalance(std::vector<std::string> cameraNames, double minGain, double maxGain,
                             double smoothing, std::string_view reference)
    : names_(std::move(cameraNames)),
      minGain_(minGain),
      maxGain_(maxGain),
      smoothing_(smoothing),
      reference_(cameraNamed(names_, reference)),
      gains_(names_.size(), cv::Vec3f(1, 1, 1)),
      logGains_(names_.size(), cv::Vec3d(0, 0, 0)),
      fitted_(names_.size(), 0),
      saidClamped_(names_.size(), 0) {
  const auto n = static_cast<int>(names_.size());
  normal_.create(n, n, CV_64F);
  rhs_.create(n, 3, CV_64F);
  solution_.create(n, 3, CV_64F);
}

void ColourBalance::update(std::span<const CameraPairRatio> pairs,
                           std::span<const std::uint8_t> present) {
  notes_.clear();
  const std::size_t n = names_.size();
  // Which cameras the pairs tie together this set: only they are fitted.
  std::fill(fitted_.begin(), fitted_.end(), 0);
  for (const auto& pair : pairs) {
    if (pair.weight <= 0 || present[pair.a] == 0 || present[pair.b] == 0) continue;
    fitted_[pair.a] = fitted_[pair.b] = 1;
  }
  const auto fittedCount = std::count(fitted_.begin(), fitted_.end(), 1);
  // Without its reference, a set cannot say where the others go.
  if (fittedCount < 2 || (reference_ && fitted_[*reference_] == 0)) return;
  // Per channel: minimize sum_pairs w (x_a - x_b - r)^2 + anchor (sum over fitted cameras x)^2,
  // x = log gain, r = log(b / a): after the balance g_a a = g_b b, so x_a - x_b = r. With a
  // reference camera the anchor is its own x^2 instead. Cameras not fitted get a row of their own
  // that keeps them at 0 (their gains are left as they are).
  normal_.setTo(0);
  rhs_.setTo(0);
  const auto at = [&](std::size_t i, std::size_t j) -> double& {
    return normal_.at<double>(static_cast<int>(i), static_cast<int>(j));
  };
  for (const auto& pair : pairs) {
    if (pair.weight <= 0 || present[pair.a] == 0 || present[pair.b] == 0) continue;
    at(pair.a, pair.a) += pair.weight;
    at(pair.b, pair.b) += pair.weight;
    at(pair.a, pair.b) -= pair.weight;
    at(pair.b, pair.a) -= pair.weight;
    for (int c = 0; c < 3; ++c) {
      rhs_.at<double>(pair.a, c) += pair.weight * pair.logRatio[c];
      rhs_.at<double>(pair.b, c) -= pair.weight * pair.logRatio[c];
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (fitted_[i] == 0) {
      at(i, i) = 1;
    } else if (reference_) {
      if (i == *reference_) at(i, i) += kAnchorWeight;
    } else {
      for (std::size_t j = 0; j < n; ++j) {
        if (fitted_[j] != 0) at(i, j) += kAnchorWeight;
      }
    }
  }
  if (!cv::solve(normal_, rhs_, solution_, cv::DECOMP_CHOLESKY)) return;
  const double keep = first_ ? 0.0 : smoothing_;
  first_ = false;
  for (std::size_t i = 0; i < n; ++i) {
    if (fitted_[i] == 0) continue;
    bool clamped = false;
    double furthest = 1;
    for (int c = 0; c < 3; ++c) {
      double& smoothed = logGains_[i][c];
      smoothed = keep * smoothed + (1 - keep) * solution_.at<double>(static_cast<int>(i), c);
      const double gain = std::exp(smoothed);
      const double bounded = std::clamp(gain, minGain_, maxGain_);
      if (bounded != gain) {
        clamped = true;
        if (std::abs(std::log(gain)) > std::abs(std::log(furthest))) furthest = gain;
      }
      gains_[i][c] = static_cast<float>(bounded);
    }
    if (clamped && saidClamped_[i] == 0) {
      saidClamped_[i] = 1;
      notes_.push_back(fmt::format(
          "balance: camera '{}' would need a gain of {:.2f}, outside {:g}..{:g}: clamped; its "
          "ground disagrees with its neighbours' more than exposure and white balance explain",
          names_[i], furthest, minGain_, maxGain_));
    }
  }
}

}  // namespace surroundd::processing
