#pragma once
// What is wrong with each camera, judged from the frame sets as they leave the synchronizer:
//   lost        no frame for `lostAfter` of set time (unplugged, stalled, its stream ended);
//   frozen      `frozenFrames` frames in a row whose pixels differ from the previous frame's by
//               less than `frozenChange` on average (a driver or link repeating one buffer; a
//               lossy codec wobbles a repeated picture by up to about 0.9 level, while a live
//               sensor's noise alone changes it by more: 1.7 levels at sigma 1.5), or whose
//               timestamps stop moving (the synchronizer drops those frames). Off for a camera
//               that shows one picture by design (a still picture, looped): see setFrozenCheck;
//   black       mean level under `blackLevel` (lens covered, sensor dead);
//   saturated   mean level over `saturatedLevel` (blinded);
//   out of sync its frames keep arriving but miss the sets (dropped as unmatched `outOfSyncSets`
//               times in a row).
// Each frame is looked at through a sparse grid of samples, so the cost per frame is a few
// hundred pixel reads. Pure logic: no clocks, no threads; the set timestamps are the time.

#include <array>
#include <cstdint>
#include <vector>

#include "capture/frame_set.hpp"
#include "capture/synchronizer.hpp"

namespace surroundd::capture {

enum class CameraHealth { kOk, kLost, kFrozen, kBlack, kSaturated, kOutOfSync };
const char* toString(CameraHealth health);

struct HealthSettings {
  Timestamp lostAfter = std::chrono::milliseconds(100);
  int frozenFrames = 3;
  double frozenChange = 1.0;  // mean absolute change per sample, 8-bit levels
  double blackLevel = 12;
  double saturatedLevel = 243;
  int outOfSyncSets = 3;
};

struct HealthChange {
  std::size_t camera = 0;
  CameraHealth from = CameraHealth::kOk;
  CameraHealth to = CameraHealth::kOk;
  Timestamp at{0};  // the set timestamp at which it was seen
};

class CameraHealthMonitor {
 public:
  CameraHealthMonitor(std::size_t cameraCount, HealthSettings settings = {});

  // Looks at one set; `sync` is the synchronizer's statistics after it. Returns the changes it
  // saw (a view valid until the next call; empty almost always).
  const std::vector<HealthChange>& observe(const FrameSet& set, const SyncStats& sync);

  CameraHealth health(std::size_t camera) const { return cameras_[camera].health; }

  // On by default. Off, the camera is never judged frozen: its frames may repeat by design. A
  // camera whose timestamps stop is then found lost instead, once its frames stop coming.
  void setFrozenCheck(std::size_t camera, bool enabled) { cameras_[camera].frozenCheck = enabled; }
  bool frozenCheck(std::size_t camera) const { return cameras_[camera].frozenCheck; }

 private:
  static constexpr int kSamplesAcross = 32;
  static constexpr int kSamplesDown = 18;
  struct Camera {
    CameraHealth health = CameraHealth::kOk;
    bool frozenCheck = true;
    std::optional<Timestamp> lastFrame;
    std::array<std::uint8_t, static_cast<std::size_t>(kSamplesAcross) * kSamplesDown * 3> samples{};
    int sameFrames = 0;  // consecutive frames whose samples equal the previous frame's
    std::uint64_t unmatchedBefore = 0;
    std::uint64_t outOfOrderBefore = 0;
    int unmatchedSets = 0;
  };
  CameraHealth judge(Camera& camera, const Frame* frame, Timestamp now, std::uint64_t unmatched,
                     std::uint64_t outOfOrder);

  HealthSettings settings_;
  std::vector<Camera> cameras_;
  std::optional<Timestamp> firstSet_;
  std::vector<HealthChange> changes_;
};

}  // namespace surroundd::capture
