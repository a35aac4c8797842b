#pragma once
// Groups one frame per camera into a FrameSet by timestamp.
//
// The synchronizer holds at most one frame per camera (its "head"). Once every running camera has a
// head, heads more than `tolerance` older than the newest head cannot belong to the newest set:
// they are dropped (counted per camera) and their cameras must offer their next frame. When all
// heads lie within the tolerance they leave together as one set. A camera that has ended leaves an
// empty slot in every later set; the others go on.
//
// Live cameras do not wait for each other forever: popLate() lets a set go without the cameras
// that have not delivered by a deadline (their slots empty, counted as late).
//
// Pure logic, no threads or clocks: the caller feeds frames (needs() says which camera to read
// next) and, live, the time, which makes every case testable with timestamps alone.

#include <array>
#include <cstdint>
#include <optional>

#include "capture/frame_set.hpp"

namespace surroundd::capture {

struct SyncStats {
  std::uint64_t setsEmitted = 0;
  std::array<std::uint64_t, kMaxCameras> unmatchedDropped{};   // frames with no partner in time
  std::array<std::uint64_t, kMaxCameras> outOfOrderDropped{};  // timestamps that went backwards
  std::array<std::uint64_t, kMaxCameras> lateMissing{};        // sets sent without this camera
  Timestamp maxSpread{0};    // largest newest-minus-oldest timestamp within an emitted set
  Timestamp spreadTotal{0};  // summed over emitted sets, for the mean skew

  std::uint64_t totalDropped() const;
  Timestamp meanSpread() const;
};

class Synchronizer {
 public:
  Synchronizer(std::size_t cameraCount, Timestamp tolerance);

  // True when `camera` is running and has no head: offer its next frame (or end it).
  bool needs(std::size_t camera) const;
  void offer(std::size_t camera, FrameRef frame);
  // The camera delivers no more frames (end of stream or given up); later sets leave its slot
  // empty.
  void end(std::size_t camera);

  // A complete set once every running camera has offered a frame and the heads line up.
  std::optional<FrameSet> pop();
  // Live: when the oldest head waited longer than `deadline` at time `now` (the cameras' clock)
  // for cameras that have not delivered, the heads that line up leave as a set without them.
  std::optional<FrameSet> popLate(Timestamp now, Timestamp deadline);
  // Every camera has ended.
  bool finished() const;

  std::size_t cameraCount() const { return cameraCount_; }
  const SyncStats& stats() const { return stats_; }

 private:
  bool allHeadsPresent() const;
  // Drops heads further than the tolerance before the newest; true if it dropped any.
  bool dropUnmatched(Timestamp newest);
  FrameSet emit(Timestamp newest);

  std::size_t cameraCount_;
  Timestamp tolerance_;
  std::array<FrameRef, kMaxCameras> heads_;
  std::array<bool, kMaxCameras> ended_{};
  std::array<std::optional<Timestamp>, kMaxCameras> lastTimestamp_;
  SyncStats stats_;
};

}  // namespace surroundd::capture
