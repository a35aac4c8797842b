#pragma once
// One synchronized frame per camera. A slot is empty when its camera had no matching frame
// (ended, lost, or dropped by the synchronizer).

#include <array>
#include <cstddef>

#include "capture/frame.hpp"

namespace surroundd::capture {

// A rig has at most this many cameras; fixed so that a FrameSet never allocates.
inline constexpr std::size_t kMaxCameras = 8;

struct FrameSet {
  std::array<FrameRef, kMaxCameras> frames;
  std::size_t cameraCount = 0;
  Timestamp timestamp{0};      // the latest member timestamp: when the set was complete
  std::uint64_t sequence = 0;  // counts emitted sets from 0

  const Frame* frame(std::size_t camera) const { return frames[camera].get(); }
};

}  // namespace surroundd::capture
