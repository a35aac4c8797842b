#include "capture/synchronizer.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace surroundd::capture {

std::uint64_t SyncStats::totalDropped() const {
  return std::accumulate(unmatchedDropped.begin(), unmatchedDropped.end(), std::uint64_t{0}) +
         std::accumulate(outOfOrderDropped.begin(), outOfOrderDropped.end(), std::uint64_t{0});
}

Timestamp SyncStats::meanSpread() const {
  return setsEmitted > 0 ? spreadTotal / static_cast<std::int64_t>(setsEmitted) : Timestamp(0);
}

Synchronizer::Synchronizer(std::size_t cameraCount, Timestamp tolerance)
    : cameraCount_(cameraCount), tolerance_(tolerance) {
  if (cameraCount == 0 || cameraCount > kMaxCameras) {
    throw std::invalid_argument("Synchronizer: camera count must be 1.." +
                                std::to_string(kMaxCameras));
  }
}

bool Synchronizer::needs(std::size_t camera) const { return !ended_[camera] && !heads_[camera]; }

void Synchronizer::offer(std::size_t camera, FrameRef frame) {
  // A timestamp that does not move forward is a broken source, not a frame of a later set.
  if (lastTimestamp_[camera] && frame->timestamp <= *lastTimestamp_[camera]) {
    ++stats_.outOfOrderDropped[camera];
    return;
  }
  lastTimestamp_[camera] = frame->timestamp;
  heads_[camera] = std::move(frame);
}

void Synchronizer::end(std::size_t camera) {
  ended_[camera] = true;
  heads_[camera].reset();
}

bool Synchronizer::finished() const {
  return std::all_of(ended_.begin(), ended_.begin() + static_cast<std::ptrdiff_t>(cameraCount_),
                     [](bool ended) { return ended; });
}

bool Synchronizer::allHeadsPresent() const {
  bool any = false;
  for (std::size_t c = 0; c < cameraCount_; ++c) {
    if (ended_[c]) continue;
    if (!heads_[c]) return false;
    any = true;
  }
  return any;
}

std::optional<FrameSet> Synchronizer::pop() {
  if (!allHeadsPresent()) return std::nullopt;
  Timestamp newest = Timestamp::min();
  for (std::size_t c = 0; c < cameraCount_; ++c) {
    if (heads_[c]) newest = std::max(newest, heads_[c]->timestamp);
  }
  if (dropUnmatched(newest)) return std::nullopt;
  return emit(newest);
}

std::optional<FrameSet> Synchronizer::popLate(Timestamp now, Timestamp deadline) {
  Timestamp newest = Timestamp::min();
  Timestamp oldest = Timestamp::max();
  for (std::size_t c = 0; c < cameraCount_; ++c) {
    if (!heads_[c]) continue;
    newest = std::max(newest, heads_[c]->timestamp);
    oldest = std::min(oldest, heads_[c]->timestamp);
  }
  if (newest == Timestamp::min() || now - oldest <= deadline) return std::nullopt;
  dropUnmatched(newest);
  for (std::size_t c = 0; c < cameraCount_; ++c) {
    if (!ended_[c] && !heads_[c]) ++stats_.lateMissing[c];
  }
  return emit(newest);
}

bool Synchronizer::dropUnmatched(Timestamp newest) {
  bool dropped = false;
  for (std::size_t c = 0; c < cameraCount_; ++c) {
    if (heads_[c] && newest - heads_[c]->timestamp > tolerance_) {
      heads_[c].reset();  // returns the buffer to its pool
      ++stats_.unmatchedDropped[c];
      dropped = true;
    }
  }
  return dropped;
}

FrameSet Synchronizer::emit(Timestamp newest) {
  FrameSet set;
  set.cameraCount = cameraCount_;
  set.timestamp = newest;
  set.sequence = stats_.setsEmitted++;
  Timestamp oldest = newest;
  for (std::size_t c = 0; c < cameraCount_; ++c) {
    if (heads_[c]) oldest = std::min(oldest, heads_[c]->timestamp);
    set.frames[c] = std::move(heads_[c]);
  }
  stats_.maxSpread = std::max(stats_.maxSpread, newest - oldest);
  stats_.spreadTotal += newest - oldest;
  return set;
}

}  // namespace surroundd::capture
