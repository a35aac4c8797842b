#include "processing/calibration/picture_search.hpp"

#include <algorithm>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "processing/calibration/view_acceptance.hpp"

namespace surroundd::processing {
namespace {

using Clock = std::chrono::steady_clock;

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
  std::vector<std::optional<Clock::time_point>> boundStarts;  // per worker slot
  std::vector<std::size_t> current;                           // per worker slot
  std::vector<char> abandoned;                                // per worker slot
  std::vector<std::size_t> finishOrder;
  std::size_t next = 0;
  bool stopping = false;
};

PictureSearch searchOne(const cv::Mat& gray, const CalibrationBoard& board) {
  PictureSearch result;
  result.imageSize = gray.size();
  const auto start = Clock::now();
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
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

void workerLoop(const std::shared_ptr<SearchState>& state, std::size_t slot) {
  std::unique_lock lock(state->mutex);
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
    state->boundStarts[slot] = Clock::now();
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
  auto state = std::make_shared<SearchState>(count, std::move(loader), board);
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const auto workers = static_cast<std::size_t>(
      std::min(static_cast<int>(count), options.threads > 0 ? options.threads : cores));
  std::vector<std::thread> threads;
  const auto startWorker = [&] {
    std::lock_guard lock(state->mutex);
    const std::size_t slot = state->current.size();
    state->current.push_back(0);
    state->boundStarts.emplace_back();
    state->abandoned.push_back(0);
    threads.emplace_back(workerLoop, state, slot);
  };
  for (std::size_t i = 0; i < workers; ++i) startWorker();

  std::size_t reported = 0, largerGrids = 0, found = 0;
  std::unique_lock lock(state->mutex);
  while (reported < count) {
    state->changed.wait_for(lock, std::chrono::milliseconds(50));
    // Pictures past their bound: report them, give up their workers, start new ones.
    for (std::size_t slot = 0; slot < state->boundStarts.size(); ++slot) {
      const auto& started = state->boundStarts[slot];
      if (state->abandoned[slot] || !started || Clock::now() - *started < options.perPicture) {
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
      if (result.outcome == PictureSearch::Outcome::kLargerThanBoard) ++largerGrids;
      if (result.outcome == PictureSearch::Outcome::kFound) ++found;
      lock.unlock();
      if (progress) progress(index, result, reported);
      lock.lock();
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
