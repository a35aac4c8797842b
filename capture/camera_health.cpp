#include "capture/camera_health.hpp"

#include <algorithm>
#include <cstdlib>

namespace surroundd::capture {

const char* toString(CameraHealth health) {
  switch (health) {
    case CameraHealth::kOk:
      return "ok";
    case CameraHealth::kLost:
      return "lost";
    case CameraHealth::kFrozen:
      return "frozen";
    case CameraHealth::kBlack:
      return "black";
    case CameraHealth::kSaturated:
      return "saturated";
    case CameraHealth::kOutOfSync:
      return "out of sync";
  }
  return "?";
}

CameraHealthMonitor::CameraHealthMonitor(std::size_t cameraCount, HealthSettings settings)
    : settings_(settings), cameras_(cameraCount) {
  changes_.reserve(cameraCount);
}

const std::vector<HealthChange>& CameraHealthMonitor::observe(const FrameSet& set,
                                                              const SyncStats& sync) {
  changes_.clear();
  if (!firstSet_) firstSet_ = set.timestamp;
  for (std::size_t c = 0; c < cameras_.size(); ++c) {
    Camera& camera = cameras_[c];
    const CameraHealth now = judge(camera, set.frame(c), set.timestamp, sync.unmatchedDropped[c],
                                   sync.outOfOrderDropped[c]);
    if (now != camera.health) {
      changes_.push_back({c, camera.health, now, set.timestamp});
      camera.health = now;
    }
  }
  return changes_;
}

CameraHealth CameraHealthMonitor::judge(Camera& camera, const Frame* frame, Timestamp now,
                                        std::uint64_t unmatched, std::uint64_t outOfOrder) {
  // A frame whose timestamp did not move on is a repeat, whatever its pixels.
  const bool repeatedTimestamp = outOfOrder > camera.outOfOrderBefore;
  camera.outOfOrderBefore = outOfOrder;
  if (repeatedTimestamp) ++camera.sameFrames;
  // Frames that keep being dropped for want of partners, while the camera delivers.
  const bool missedSet = unmatched > camera.unmatchedBefore;
  camera.unmatchedBefore = unmatched;
  camera.unmatchedSets = missedSet && frame == nullptr ? camera.unmatchedSets + 1 : 0;

  if (frame == nullptr) {
    if (camera.unmatchedSets >= settings_.outOfSyncSets) return CameraHealth::kOutOfSync;
    if (camera.frozenCheck && repeatedTimestamp &&
        camera.sameFrames + 1 >= settings_.frozenFrames) {
      return CameraHealth::kFrozen;
    }
    const Timestamp since = now - camera.lastFrame.value_or(*firstSet_);
    return since > settings_.lostAfter ? CameraHealth::kLost : camera.health;
  }
  camera.lastFrame = now;

  const cv::Size size = pictureSize(frame->format, frame->image);
  std::array<std::uint8_t, static_cast<std::size_t>(kSamplesAcross) * kSamplesDown * 3> samples{};
  std::uint64_t sum = 0;
  std::size_t index = 0;
  for (int j = 0; j < kSamplesDown; ++j) {
    const int row = (2 * j + 1) * size.height / (2 * kSamplesDown);
    for (int i = 0; i < kSamplesAcross; ++i) {
      const int column = (2 * i + 1) * size.width / (2 * kSamplesAcross);
      const std::uint32_t pixel = bgrAt(frame->image, frame->format, column, row);
      for (int k = 0; k < 3; ++k) {
        const auto level = static_cast<std::uint8_t>(pixel >> (8 * k));
        samples[index++] = level;
        sum += level;
      }
    }
  }
  int change = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    change += std::abs(static_cast<int>(samples[i]) - static_cast<int>(camera.samples[i]));
  }
  const bool same =
      static_cast<double>(change) < settings_.frozenChange * static_cast<double>(samples.size());
  camera.sameFrames = same ? camera.sameFrames + 1 : 0;
  camera.samples = samples;
  const double mean = static_cast<double>(sum) / static_cast<double>(samples.size());
  if (mean < settings_.blackLevel) return CameraHealth::kBlack;
  if (mean > settings_.saturatedLevel) return CameraHealth::kSaturated;
  // n frames with the same pixels are n - 1 repeats of the first.
  if (camera.frozenCheck && camera.sameFrames + 1 >= settings_.frozenFrames) {
    return CameraHealth::kFrozen;
  }
  return CameraHealth::kOk;
}

}  // namespace surroundd::capture
