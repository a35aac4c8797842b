#pragma once
// Where the pipeline thread's time goes, per Stage (pipeline_report.hpp): summed over the run and,
// per frame set, into one histogram per stage that the set went through. Pipeline thread only.

#include <array>
#include <bitset>
#include <chrono>

#include "daemon/duration_histogram.hpp"
#include "daemon/pipeline_report.hpp"

namespace surroundd::daemon {

class StageTimes {
 public:
  using Clock = std::chrono::steady_clock;

  // Waiting for the cameras' frames: the next set's sync time (also while no set comes).
  void waited(Clock::duration time) { add(Stage::kSync, time); }
  // A set is complete: its sync time counts, and its stages' times start now.
  void beginSet();
  // The time since the last lap (or beginSet()) was `stage`'s.
  void lap(Stage stage);
  // The time since the last lap belongs to no stage.
  void skip() { since_ = Clock::now(); }
  // The set went through: each stage it went through gets its time in its histogram.
  void endSet();
  // The set was dropped: its times stay in the run's sums only.
  void dropSet();

  const std::array<std::chrono::nanoseconds, kStageCount>& totals() const { return totals_; }
  const std::array<DurationHistogram, kStageCount>& histograms() const { return histograms_; }

 private:
  void add(Stage stage, Clock::duration time);

  Clock::time_point since_{};
  std::array<std::chrono::nanoseconds, kStageCount> totals_{};  // summed over the run
  std::array<std::chrono::nanoseconds, kStageCount> set_{};     // this set's
  std::bitset<kStageCount> setRan_;
  std::array<DurationHistogram, kStageCount> histograms_;
};

}  // namespace surroundd::daemon
