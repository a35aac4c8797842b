#pragma once
// Global colour balance (issue 49): one gain per camera and channel that brings the cameras'
// colours together over the ground they share, before any local correction. Each camera has its
// own exposure and white balance; a local correction alone pulls each band towards its
// neighbour's tint (a pinkish camera turns the band beside it pink). The balance instead takes
// every camera to the cameras' average: the mean over the cameras of each channel's log gain is 0,
// so the panorama's brightness and its grey-world neutral stay where the cameras have them on
// average, and no camera's tint wins. Or, where the user names one (a camera whose colour is known
// to be right), to that camera: its gains stay 1, and a set without it changes no gains.
//
// The fit is least squares over the pairs of cameras that share ground: for each pair, the
// median over its measured seam blocks of log(level b / level a) per channel (robust to objects
// on the seam and to the odd clipped block), weighted by how many blocks measured it. It is
// smoothed over time (`smoothing`: the previous set's share), so that noise does not flicker while
// an exposure change is followed within a few sets; a camera missing from a set keeps its gains.
// Gains outside [minGain, maxGain] are clamped and said once per camera.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

namespace surroundd::processing {

// Two cameras' levels on the ground they both see: log(b's / a's), per channel, and how much
// ground measured it (blocks, or any count).
struct CameraPairRatio {
  std::uint8_t a = 0, b = 0;
  cv::Vec3f logRatio;
  double weight = 0;
};

class ColourBalance {
 public:
  // Camera names are for the notes. `reference`: the name of the camera the others are taken to;
  // empty: their average. Throws std::invalid_argument for a name none of the cameras has.
  ColourBalance(std::vector<std::string> cameraNames, double minGain, double maxGain,
                double smoothing, std::string_view reference = {});

  // Fits this set's gains from the pairs measured in it; `present[c]` false: camera c is not in
  // the set (its gains stay, and it does not count towards the average). A camera present but in
  // no pair keeps its gains too. Allocates nothing after the first call.
  void update(std::span<const CameraPairRatio> pairs, std::span<const std::uint8_t> present);

  // Per camera, B G R gains; all 1 before the first update.
  const std::vector<cv::Vec3f>& gains() const { return gains_; }
  // What the last update() clamped, the first time for each camera, to be logged.
  const std::vector<std::string>& notesOfLastUpdate() const { return notes_; }

 private:
  std::vector<std::string> names_;
  double minGain_, maxGain_, smoothing_;
  std::optional<std::size_t> reference_;
  std::vector<cv::Vec3f> gains_;
  std::vector<cv::Vec3d> logGains_;  // smoothed, before clamping
  bool first_ = true;
  cv::Mat normal_, rhs_, solution_;  // the fit's normal equations, reused
  std::vector<std::uint8_t> fitted_, saidClamped_;
  std::vector<std::string> notes_;
};

}  // namespace surroundd::processing
