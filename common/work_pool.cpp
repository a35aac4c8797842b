#include "common/work_pool.hpp"

#include <algorithm>
#include <utility>

namespace surroundd {

WorkPool::WorkPool(int threads) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  workers_.reserve(static_cast<std::size_t>(threads - 1));
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { workerLoop(); });
}

WorkPool::~WorkPool() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (auto& worker : workers_) worker.join();
}

void WorkPool::run(int count, int chunks, void* callable, Trampoline trampoline) {
  if (count <= 0) return;
  if (chunks <= 0) chunks = threads();
  chunks = std::min(chunks, count);
  if (chunks == 1 || workers_.empty()) {
    trampoline(callable, 0, count);
    return;
  }
  {
    const std::lock_guard lock(mutex_);
    callable_ = callable;
    trampoline_ = trampoline;
    count_ = count;
    chunks_ = chunks;
    nextChunk_ = 0;
    unfinished_ = chunks;
    ++generation_;
  }
  wake_.notify_all();
  takeChunks();
  std::unique_lock lock(mutex_);
  done_.wait(lock, [this] { return unfinished_ == 0; });
  if (failure_) std::rethrow_exception(std::exchange(failure_, nullptr));
}

void WorkPool::takeChunks() {
  std::unique_lock lock(mutex_);
  while (nextChunk_ < chunks_) {
    const int chunk = nextChunk_++;
    // Chunk boundaries depend only on (count, chunks), so the split is the same on every call.
    const int begin = static_cast<int>(static_cast<long long>(count_) * chunk / chunks_);
    const int end = static_cast<int>(static_cast<long long>(count_) * (chunk + 1) / chunks_);
    void* callable = callable_;
    const Trampoline trampoline = trampoline_;
    lock.unlock();
    std::exception_ptr failure;
    try {
      trampoline(callable, begin, end);
    } catch (...) {
      failure = std::current_exception();
    }
    lock.lock();
    if (failure) {
      if (!failure_) failure_ = failure;
      // The chunks not handed out yet are dropped: the loop has failed.
      unfinished_ -= chunks_ - nextChunk_;
      nextChunk_ = chunks_;
    }
    if (--unfinished_ == 0) done_.notify_one();
  }
}

void WorkPool::workerLoop() {
  std::size_t seen = 0;
  for (;;) {
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stopping_ || generation_ != seen; });
      if (stopping_) return;
      seen = generation_;
    }
    takeChunks();
  }
}

}  // namespace surroundd
