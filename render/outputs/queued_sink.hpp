#pragma once
// Runs a FrameSink (an encoder) on a thread of its own behind a bounded queue of preallocated
// pictures, so that encoding and sending one frame set overlap stitching and rendering the next.
//
// When the queue is full: kWait blocks the caller (a replay stays lossless and is paced by its
// slowest output), kDropOldest replaces the oldest waiting picture (live: the newest wins, and
// each drop is counted; a stuck output never holds up the cameras).
//
// Threads: consume() and finish() are called by the pipeline thread; the wrapped sink's consume()
// runs on the worker, its finish() and describe() on the caller after the worker has ended. The
// queue below is all they share, besides the wrapped sink's wantsFrame() and page(), which are
// asked on the caller while the worker may be in its consume() (FrameSink's contract). A failure on
// the worker is rethrown by the next consume() or by finish(), so the pipeline drops the output as
// it would any other.

#include <condition_variable>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "render/outputs/frame_sink.hpp"

namespace surroundd::render {

class QueuedSink final : public FrameSink {
 public:
  enum class WhenFull { kWait, kDropOldest };

  // Pictures are of `size`; `depth` of them can wait.
  QueuedSink(std::unique_ptr<FrameSink> sink, cv::Size size, std::size_t depth, WhenFull whenFull);
  ~QueuedSink() override;  // without finish(): stops the worker; the sink finalizes itself

  void consume(const cv::Mat& picture, const PictureTime& time) override;
  void finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) override;
  std::string describe() const override;
  // The wrapped sink's: a picture nobody wants is neither made nor queued.
  bool wantsFrame(std::chrono::nanoseconds streamTime) const override;
  ViewPage* page() override { return sink_->page(); }
  bool takesI420() const override { return sink_->takesI420(); }

  std::uint64_t dropped() const override;

 private:
  struct Item {
    std::size_t slot = 0;
    PictureTime time{std::chrono::nanoseconds(0)};
  };
  void work();
  void stopWorker();

  std::unique_ptr<FrameSink> sink_;
  WhenFull whenFull_;
  std::size_t depth_;           // pictures that may wait
  std::vector<cv::Mat> slots_;  // depth + 1: one more for the picture the worker is consuming

  mutable std::mutex mutex_;  // guards the queue, the free slots, the counters and the failure
  std::condition_variable changed_;
  // Ring of depth + 1 items (as many as slots), oldest at head_; at most depth_ are waiting.
  std::vector<Item> queue_;
  std::size_t head_ = 0;
  std::size_t size_ = 0;
  std::vector<std::size_t> free_;  // slots that are neither queued nor being consumed
  bool stopping_ = false;
  std::exception_ptr failure_;
  std::uint64_t dropped_ = 0;

  std::thread worker_;
};

}  // namespace surroundd::render
