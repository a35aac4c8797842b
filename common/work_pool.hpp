#pragma once
// A fixed set of worker threads that split one loop at a time between them and the caller.
//
// Built once at start-up; parallelFor() allocates nothing, so the per-frame stages (stitch, colour
// correction) can use it. One loop runs at a time: parallelFor() is not reentrant and must be
// called from one thread (the stage that owns the pool).

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace surroundd {

class WorkPool {
 public:
  // `threads` counts the caller too: 1 runs everything on the caller; 0 means one per core.
  explicit WorkPool(int threads = 0);
  ~WorkPool();
  WorkPool(const WorkPool&) = delete;
  WorkPool& operator=(const WorkPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Calls body(begin, end) on disjoint chunks that together cover [0, count), in parallel, and
  // returns when all are done. `chunks` (default: one per thread) sets how finely the range is cut;
  // more chunks balance uneven work better. An exception from the body (on any thread) stops the
  // chunks not yet begun, and the first one is rethrown here once every running chunk is done;
  // the pool stays usable.
  template <typename Body>
  void parallelFor(int count, Body&& body, int chunks = 0) {
    using Callable = std::remove_reference_t<Body>;
    run(count, chunks, &body, [](void* callable, int begin, int end) {
      (*static_cast<Callable*>(callable))(begin, end);
    });
  }

 private:
  using Trampoline = void (*)(void*, int, int);
  void run(int count, int chunks, void* callable, Trampoline trampoline);
  void workerLoop();
  void takeChunks();

  std::vector<std::thread> workers_;
  // The current loop; written by run() under mutex_ before the generation changes, read by the
  // workers after they see the new generation.
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  std::size_t generation_ = 0;
  bool stopping_ = false;
  void* callable_ = nullptr;
  Trampoline trampoline_ = nullptr;
  int count_ = 0;
  int chunks_ = 0;
  int nextChunk_ = 0;           // next chunk to hand out
  int unfinished_ = 0;          // chunks not yet finished
  std::exception_ptr failure_;  // the first exception of the current loop
};

}  // namespace surroundd
