#pragma once
// The calibration watch's mount refinement (processing/calibration/mount_refinement.hpp), on a
// thread of its own: comparing a set's ground patches takes tens of milliseconds, which the
// pipeline thread must not wait for. The pipeline offers a set now and then; the worker takes it
// when it is idle (a set offered while it is busy is skipped: the road goes on), adds its
// comparisons, and every few sets solves (MountRefinement::track); the latest solution is read
// back at any time.
//
// Threads: the pipeline thread calls offer() and latest(); the worker thread alone touches the
// refinement. The pictures offered and the latest solution are handed over under mutex_; the
// pictures' buffers are allocated once, at the first offer.

#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <optional>
#include <span>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/mount_refinement.hpp"
#include "processing/rig.hpp"

namespace surroundd::daemon {

struct MountCorrectionState {
  std::optional<processing::MountRefinementResult> result;  // none until enough ground was seen
  std::size_t setsCompared = 0;
  std::size_t solutions = 0;  // solved so far: a new one each time it grows
  double cpuSeconds = 0;      // the worker's own, so far
};

class MountCorrectionWorker {
 public:
  // Solves after every `solveEvery` sets compared.
  MountCorrectionWorker(const processing::Rig& rig, const processing::PanoramaSettings& settings,
                        std::size_t solveEvery = 10);
  ~MountCorrectionWorker();
  MountCorrectionWorker(const MountCorrectionWorker&) = delete;
  MountCorrectionWorker& operator=(const MountCorrectionWorker&) = delete;

  // One picture per camera (8-bit BGR; null where missing or faulty). Copied when the worker is
  // idle (returns true), else skipped.
  bool offer(std::span<const cv::Mat* const> pictures);
  // Whether an offer now would be taken: the pipeline asks before it converts a set's pictures.
  bool idle() const;
  MountCorrectionState latest() const;

 private:
  void run(const std::stop_token& stop);

  processing::MountRefinement refinement_;  // the worker thread's alone
  std::size_t solveEvery_;
  std::vector<cv::Mat> pictures_;  // the set handed over: written by offer() while !busy_
  std::vector<bool> present_;
  mutable std::mutex mutex_;
  std::condition_variable_any wake_;
  bool busy_ = false;           // under mutex_: the worker owns pictures_ while true
  MountCorrectionState state_;  // under mutex_
  std::jthread thread_;         // last: it starts once the rest is made
};

}  // namespace surroundd::daemon
