#pragma once
// One synchronized frame per camera. A slot is empty when its camera had no matching frame
// (ended, lost, or dropped by the synchronizer).

#include <array>
#include <cstddef>

#include "capture/frame.hpp"
#include "common/camera_limit.hpp"

namespace surroundd::capture {

// A FrameSet has a slot for each camera a rig may have, so that it never allocates.
using surroundd::kMaxCameras;

struct FrameSet {
  std::array<FrameRef, kMaxCameras> frames;
  std::size_t cameraCount = 0;
  Timestamp timestamp{0};      // the latest member timestamp: when the set was complete
  std::uint64_t sequence = 0;  // counts emitted sets from 0

  const Frame* frame(std::size_t camera) const { return frames[camera].get(); }
};

}  // namespace surroundd::capture
