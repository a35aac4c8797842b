#include "daemon/stages/mount_correction_worker.hpp"

#include <ctime>

#include <spdlog/spdlog.h>

namespace surroundd::daemon {
namespace {

double threadCpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + static_cast<double>(now.tv_nsec) * 1e-9;
}

}  // namespace

MountCorrectionWorker::MountCorrectionWorker(const processing::Rig& rig,
                                             const processing::PanoramaSettings& settings,
                                             std::size_t solveEvery)
    : refinement_(rig, settings),
      solveEvery_(std::max<std::size_t>(solveEvery, 1)),
      pictures_(rig.cameras.size()),
      present_(rig.cameras.size(), false),
      thread_([this](const std::stop_token& stop) { run(stop); }) {}

MountCorrectionWorker::~MountCorrectionWorker() {
  thread_.request_stop();
  wake_.notify_all();
}

bool MountCorrectionWorker::offer(std::span<const cv::Mat* const> pictures) {
  {
    const std::lock_guard lock(mutex_);
    if (busy_) return false;
    // While !busy_ the worker does not read pictures_: copied here, into buffers kept from set to
    // set.
    for (std::size_t c = 0; c < pictures_.size() && c < pictures.size(); ++c) {
      present_[c] = pictures[c] != nullptr;
      if (present_[c]) pictures[c]->copyTo(pictures_[c]);
    }
    busy_ = true;
  }
  wake_.notify_one();
  return true;
}

bool MountCorrectionWorker::idle() const {
  const std::lock_guard lock(mutex_);
  return !busy_;
}

MountCorrectionState MountCorrectionWorker::latest() const {
  const std::lock_guard lock(mutex_);
  return state_;
}

void MountCorrectionWorker::run(const std::stop_token& stop) {
  std::vector<const cv::Mat*> set(pictures_.size());
  while (true) {
    {
      std::unique_lock lock(mutex_);
      if (!wake_.wait(lock, stop, [this] { return busy_; })) return;
    }
    const double cpuBefore = threadCpuSeconds();
    for (std::size_t c = 0; c < set.size(); ++c) set[c] = present_[c] ? &pictures_[c] : nullptr;
    std::optional<processing::MountRefinementResult> solved;
    try {
      solved = refinement_.track(set, solveEvery_);
    } catch (const std::exception& error) {
      // A frame the refinement cannot take (its size changed on a reload) costs this set only.
      spdlog::warn("calibration watch: mount refinement skipped a set: {}", error.what());
    }
    const double cpu = threadCpuSeconds() - cpuBefore;
    const std::lock_guard lock(mutex_);
    ++state_.setsCompared;
    state_.cpuSeconds += cpu;
    if (solved) {
      state_.result = std::move(solved);
      ++state_.solutions;
    }
    busy_ = false;
  }
}

}  // namespace surroundd::daemon
