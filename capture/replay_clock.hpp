#pragma once
// The clock of a replayed camera, whether it decodes a file as it goes (FileSource) or plays
// frames held in memory (PreloadedSource): both pace and loop the same way.
//
// Real-time pacing: the first frame read is due at once, every later one when its timestamp minus
// the first's has passed since, on the steady clock (ReplayStart). As fast as possible: no wait.
// Looping: timestamps move on by a whole number of nominal periods past the last frame, so that the
// stream stays monotonic and the cameras of a rig loop by the same offset, whatever the jitter of
// their last frames' timestamps (which would otherwise pull them apart, pass by pass).

#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <thread>

#include "capture/frame.hpp"

namespace surroundd::capture {

enum class Pacing { kRealtime, kAsFastAsPossible };

// Where a replay's clock starts: the first frame read is due when it is read, every later one when
// its timestamp minus that first one's has passed since. One start serves all the replayed cameras
// of a rig, each reading on its own thread: their frames of one instant are then due together, as
// from cameras triggered together. (With a clock per camera, each started at its own first read,
// four preloaded 1080p cameras ran up to 25 ms apart, and every set waited for the last of them.)
class ReplayStart {
 public:
  using Clock = std::chrono::steady_clock;

  // When the frame stamped `timestamp` is due; the first call (from any thread) fixes the start.
  Clock::time_point due(Timestamp timestamp) {
    std::call_once(set_, [&] {
      at_ = Clock::now();
      first_ = timestamp;
    });
    // call_once orders the writes above before every caller's reads.
    return at_ + (timestamp - first_);
  }

 private:
  std::once_flag set_;
  Clock::time_point at_;
  Timestamp first_{0};
};

class ReplayPacer {
 public:
  // `start`: shared with the rig's other replayed cameras; none: this camera's own.
  explicit ReplayPacer(Pacing pacing, std::shared_ptr<ReplayStart> start = nullptr)
      : pacing_(pacing), start_(start ? std::move(start) : std::make_shared<ReplayStart>()) {}

  // Waits until the frame stamped `timestamp` is due (kRealtime).
  void waitFor(Timestamp timestamp) {
    if (pacing_ != Pacing::kRealtime) return;
    std::this_thread::sleep_until(start_->due(timestamp));
  }

 private:
  Pacing pacing_;
  std::shared_ptr<ReplayStart> start_;
};

// How far the timestamps of the next pass move on from this one's, whose frames lie from `first`
// to `last`, `period` apart.
inline Timestamp loopShift(Timestamp first, Timestamp last, Timestamp period) {
  const auto periods = std::llround(static_cast<double>((last - first).count()) /
                                    static_cast<double>(period.count()));
  return (periods + 1) * period;
}

}  // namespace surroundd::capture
