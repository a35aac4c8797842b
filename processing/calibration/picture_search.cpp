#include "processing/calibration/picture_search.hpp"

#include <algorithm>
#include <condition_variable>
#include <ctime>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include <opencv2/core/utility.hpp>
#include <pthread.h>

#include "processing/calibration/view_acceptance.hpp"

namespace surroundd::processing {
namespace {

// The CPU time a thread has used (its CPU clock, from pthread_getcpuclockid).
std::chrono::nanoseconds cpuTime(clockid_t clock) {
  timespec now{};
  ::clock_gettime(clock, &now);
  return std::chrono::seconds(now.tv_sec) + std::chrono::nanoseconds(now.tv_nsec);
}

clockid_t thisThreadsCpuClock() {
  clockid_t clock = CLOCK_THREAD_CPUTIME_ID;
  ::pthread_getcpuclockid(::pthread_self(), &clock);
  return clock;
}

// OpenCV's own threads off while the pictures are searched (they are searched in parallel
// already), so that all of a search's work is on its worker's CPU clock; as it was after.
class OpenCvThreadsOff {
 public:
  OpenCvThreadsOff() : threads_(cv::getNumThreads()) { cv::setNumThreads(1); }
  ~OpenCvThreadsOff() { cv::setNumThreads(threads_); }
  OpenCvThreadsOff(const OpenCvThreadsOff&) = delete;
  OpenCvThreadsOff& operator=(const OpenCvThreadsOff&) = delete;

 private:
  int threads_;
};

// Everything a worker touches, shared with the caller: an abandoned worker may outlive the call.
struct SearchState {
  SearchState(std::size_t count, PictureLoader load, const CalibrationBoard& searched)
      : loader(std::move(load)), board(searched), results(count), finished(count) {}

  PictureLoader loader;  // only used before a picture's bound starts (see workerLoop)
  const CalibrationBoard board;
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<PictureSearch> results;
  std::vector<char> finished;
  // Per worker slot: its thread's CPU clock, and that clock's reading when its picture's search
  // began (none between pictures).
  std::vector<clockid_t> cpuClocks;
  std::vector<std::optional<std::chrono::nanoseconds>> boundStarts;
  std::vector<std::size_t> current;  // per worker slot
  std::vector<char> abandoned;       // per worker slot
  std::vector<std::size_t> finishOrder;
  std::size_t next = 0;
  bool stopping = false;
};

PictureSearch searchOne(const cv::Mat& gray, const CalibrationBoard& board) {
  PictureSearch result;
  result.imageSize = gray.size();
  const clockid_t cpu = thisThreadsCpuClock();
  const auto start = cpuTime(cpu);
  auto found = findBoard(gray, board);
  result.seenGrid = found.seenGrid;
  switch (found.outcome) {
    case BoardSearch::Outcome::kFound:
      result.outcome = PictureSearch::Outcome::kFound;
      result.edgeWidthPx = edgeWidthPx(gray, {"", found.corners, found.grid});
      result.corners = std::move(found.corners);
      result.grid = std::move(found.grid);
      break;
    case BoardSearch::Outcome::kLargerThanBoard:
      result.outcome = PictureSearch::Outcome::kLargerThanBoard;
      break;
    case BoardSearch::Outcome::kNotFound:
      result.outcome = PictureSearch::Outcome::kNotFound;
      break;
  }
  result.seconds = std::chrono::duration<double>(cpuTime(cpu) - start).count();
  return result;
}

void workerLoop(const std::shared_ptr<SearchState>& state, std::size_t slot) {
  std::unique_lock lock(state->mutex);
  state->cpuClocks[slot] = thisThreadsCpuClock();
  while (!state->stopping && !state->abandoned[slot] && state->next < state->results.size()) {
    const std::size_t index = state->next++;
    state->current[slot] = index;
    lock.unlock();
    // The loader may borrow the caller's objects: it runs before the bound starts, so a worker
    // is never abandoned inside it.
    const cv::Mat gray = state->loader(index);
    lock.lock();
    if (state->stopping) break;
    if (gray.empty()) {
      state->results[index].outcome = PictureSearch::Outcome::kUnreadable;
      state->finished[index] = 1;
      state->finishOrder.push_back(index);
      state->changed.notify_all();
      continue;
    }
    state->boundStarts[slot] = cpuTime(state->cpuClocks[slot]);
    lock.unlock();
    PictureSearch result = searchOne(gray, state->board);
    lock.lock();
    state->boundStarts[slot].reset();
    if (!state->finished[index]) {  // else it timed out meanwhile and was reported so
      state->results[index] = std::move(result);
      state->finished[index] = 1;
      state->finishOrder.push_back(index);
      state->changed.notify_all();
    }
  }
}

}  // namespace

std::vector<PictureSearch> searchPictures(std::size_t count, PictureLoader loader,
                                          const CalibrationBoard& board,
                                          const SearchOptions& options,
                                          const SearchProgress& progress) {
  const OpenCvThreadsOff serialOpenCv;
  auto state = std::make_shared<SearchState>(count, std::move(loader), board);
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const auto workers = static_cast<std::size_t>(
      std::min(static_cast<int>(count), options.threads > 0 ? options.threads : cores));
  std::vector<std::thread> threads;
  const auto startWorker = [&] {
    std::lock_guard lock(state->mutex);
    const std::size_t slot = state->current.size();
    state->current.push_back(0);
    state->cpuClocks.push_back(CLOCK_THREAD_CPUTIME_ID);  // the worker sets its own
    state->boundStarts.emplace_back();
    state->abandoned.push_back(0);
    threads.emplace_back(workerLoop, state, slot);
  };
  for (std::size_t i = 0; i < workers; ++i) startWorker();

  std::size_t reported = 0;
  // The pictures in index order up to the first one not done yet: what the early stop looks at,
  // so that it stops alike whatever order the threads finish in.
  std::size_t prefix = 0, largerGrids = 0, found = 0;
  std::unique_lock lock(state->mutex);
  while (reported < count) {
    state->changed.wait_for(lock, std::chrono::milliseconds(50));
    // Pictures past their bound of CPU time: report them, give up their workers, start new ones.
    for (std::size_t slot = 0; slot < state->boundStarts.size(); ++slot) {
      const auto& started = state->boundStarts[slot];
      if (state->abandoned[slot] || !started ||
          cpuTime(state->cpuClocks[slot]) - *started < options.perPicture) {
        continue;
      }
      const std::size_t index = state->current[slot];
      state->results[index].outcome = PictureSearch::Outcome::kTimedOut;
      state->results[index].seconds = std::chrono::duration<double>(options.perPicture).count();
      state->finished[index] = 1;
      state->finishOrder.push_back(index);
      state->abandoned[slot] = 1;
      threads[slot].detach();
      lock.unlock();
      startWorker();
      lock.lock();
    }
    while (reported < state->finishOrder.size()) {
      const std::size_t index = state->finishOrder[reported++];
      const PictureSearch result = state->results[index];
      lock.unlock();
      if (progress) progress(index, result, reported);
      lock.lock();
    }
    for (; prefix < count && state->finished[prefix]; ++prefix) {
      const auto outcome = state->results[prefix].outcome;
      if (outcome == PictureSearch::Outcome::kLargerThanBoard) ++largerGrids;
      if (outcome == PictureSearch::Outcome::kFound) ++found;
      if (found == 0 && static_cast<int>(largerGrids) >= options.largerGridsToStop) break;
    }
    if (found == 0 && static_cast<int>(largerGrids) >= options.largerGridsToStop) break;
  }
  // Stopped early: what still runs is abandoned, what has not started is left unsearched.
  state->stopping = true;
  std::vector<PictureSearch> results = state->results;
  for (std::size_t slot = 0; slot < threads.size(); ++slot) {
    if (state->abandoned[slot]) continue;
    if (state->boundStarts[slot]) {
      state->abandoned[slot] = 1;
      threads[slot].detach();
    }
  }
  lock.unlock();
  for (auto& thread : threads) {
    if (thread.joinable()) thread.join();
  }
  return results;
}

}  // namespace surroundd::processing
