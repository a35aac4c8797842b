#pragma once
// The clock of a replayed camera, whether it decodes a file as it goes (FileSource) or plays
// frames held in memory (PreloadedSource): both pace and loop the same way.
//
// Real-time pacing: the first frame read is due at once, frame k when its timestamp minus the
// first's has passed since, on the steady clock. As fast as possible: no wait.
// Looping: timestamps move on by a whole number of nominal periods past the last frame, so that the
// stream stays monotonic and the cameras of a rig loop by the same offset, whatever the jitter of
// their last frames' timestamps (which would otherwise pull them apart, pass by pass).

#include <chrono>
#include <cmath>
#include <optional>
#include <thread>

#include "capture/frame.hpp"

namespace surroundd::capture {

enum class Pacing { kRealtime, kAsFastAsPossible };

class ReplayPacer {
 public:
  explicit ReplayPacer(Pacing pacing) : pacing_(pacing) {}

  // Waits until the frame `sinceFirst` after the replay's first frame is due (kRealtime).
  void waitFor(Timestamp sinceFirst) {
    if (pacing_ != Pacing::kRealtime) return;
    const auto now = std::chrono::steady_clock::now();
    if (!start_) start_ = now - sinceFirst;
    std::this_thread::sleep_until(*start_ + sinceFirst);
  }

 private:
  Pacing pacing_;
  std::optional<std::chrono::steady_clock::time_point> start_;
};

// How far the timestamps of the next pass move on from this one's, whose frames lie from `first`
// to `last`, `period` apart.
inline Timestamp loopShift(Timestamp first, Timestamp last, Timestamp period) {
  const auto periods = std::llround(static_cast<double>((last - first).count()) /
                                    static_cast<double>(period.count()));
  return (periods + 1) * period;
}

}  // namespace surroundd::capture
