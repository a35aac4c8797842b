#pragma once
// Everything about a recording that is decided before the first pixel: the scaled rig, each
// camera's photometrics and timing, which frames get ground truth, and the cache key. Pure
// functions of the options, the rig file and the generator, so two runs plan identically.

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "daemon/config/rig_yaml.hpp"
#include "tools/synth/photometrics.hpp"
#include "tools/synth/synth_options.hpp"

namespace surroundd::synth {

// Bump when the generator's output changes for the same arguments (the cache key includes it).
inline constexpr std::string_view kGeneratorVersion = "1";

struct CameraPlan {
  daemon::RigCamera camera;  // calibration scaled to the output size
  CameraPhotometrics photometrics;
  double startOffsetS = 0;  // 0 .. 4 ms: cameras are not triggered together
  int dropEvery = 0;        // 0: none; N: frames N-1, 2N-1, ... are not recorded
  std::optional<SynthOptions::Fault::Kind> fault;  // from faultFrame on
  int faultFrame = 0;
  // The mount from turnFrame on, where the camera is knocked.
  std::optional<processing::Pose> turnedPose;
  int turnFrame = 0;
  bool faulty(int frame, SynthOptions::Fault::Kind kind) const {
    return fault == kind && frame >= faultFrame;
  }
};

struct RecordingPlan {
  SynthOptions options;
  std::string rigText;  // the preset as read (part of the key)
  std::vector<CameraPlan> cameras;
  std::optional<daemon::VehicleConfig> vehicle;  // the preset's `vehicle:`: its body is rendered
  int frames = 0;
  std::vector<int> groundTruthFrames;  // sorted, unique
  cv::Vec3d virtualCentre;             // panorama centre, vehicle frame: (0, 0, mean camera height)
  std::string key;                     // cache key, hex

  static constexpr double kJitterS = 0.001;  // per-frame timestamp jitter, +-

  bool dropped(std::size_t camera, int frame) const;
  double frameTime(int frame) const { return frame / options.fps; }
  // Capture timestamp of a frame: nominal time + the camera's start offset + jitter, to the
  // microsecond (what the video file keeps).
  std::chrono::microseconds timestamp(std::size_t camera, int frame) const;
};

// Throws UsageError for a missing or invalid rig or a --drop-every naming no camera.
RecordingPlan planRecording(const SynthOptions& options);

// Intrinsics for a new image size; pixel centres stay pixel centres: c' = (c + 0.5) * s - 0.5.
processing::Intrinsics scaleIntrinsics(const processing::Intrinsics& in, cv::Size size);

}  // namespace surroundd::synth
