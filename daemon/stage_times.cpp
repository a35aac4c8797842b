#include "daemon/stage_times.hpp"

namespace surroundd::daemon {

void StageTimes::add(Stage stage, Clock::duration time) {
  set_[static_cast<std::size_t>(stage)] += time;
}

void StageTimes::beginSet() {
  const auto sync = static_cast<std::size_t>(Stage::kSync);
  totals_[sync] += set_[sync];
  setRan_.set(sync);
  since_ = Clock::now();
}

void StageTimes::lap(Stage stage) {
  const auto now = Clock::now();
  const auto index = static_cast<std::size_t>(stage);
  totals_[index] += now - since_;
  set_[index] += now - since_;
  setRan_.set(index);
  since_ = now;
}

void StageTimes::endSet() {
  for (std::size_t s = 0; s < kStageCount; ++s) {
    if (setRan_.test(s)) histograms_[s].record(set_[s]);
  }
  dropSet();
}

void StageTimes::dropSet() {
  set_.fill(std::chrono::nanoseconds(0));
  setRan_.reset();
}

}  // namespace surroundd::daemon
