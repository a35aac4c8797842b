#pragma once
// One camera's capture thread: reads its FrameSource into pooled frames and hands them over through
// a bounded queue, so that a slow decoder or device never stalls the other cameras' threads.
//
// Back-pressure: the pool holds `poolFrames` buffers; when the consumer keeps all of them (queued
// or in flight down the pipeline), the thread waits for one to come back instead of dropping —
// replay stays lossless. Faults go through the one recovery policy of every source kind
// (SourceRecovery: counted, logged with rate limiting, a lost device reopened with backoff, given
// up only where the settings say); the end of the stream, or the policy giving up, ends the stream.
//
// Threads: the capture thread owns the source; the queue (mutex + condition variable) is the only
// state it shares with the consumer.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "capture/frame_source.hpp"
#include "capture/source_recovery.hpp"

namespace surroundd::capture {

struct CameraStreamStats {
  std::uint64_t frames = 0;   // delivered to the queue
  std::uint64_t faults = 0;   // reads that failed, frames with concealed errors, failed reopenings
  std::uint64_t reopens = 0;  // a lost device opened again
  // Spent in the source's read() for the delivered frames: decoding and conversion, and in a
  // real-time replay the wait for each frame's time.
  std::chrono::nanoseconds readTime{0};
};

class CameraStream {
 public:
  enum class Next { kFrame, kEnded, kTimeout };

  CameraStream(std::string name, std::unique_ptr<FrameSource> source, std::size_t poolFrames,
               RecoverySettings recovery = {});
  ~CameraStream();  // stops and joins the thread
  CameraStream(const CameraStream&) = delete;
  CameraStream& operator=(const CameraStream&) = delete;

  void start();
  void stop();
  // Its frames lent the source's buffers, for a GPU to import (FrameSource::lendBuffers); why not,
  // or nullptr. Before start(): the source is the capture thread's from then on.
  const char* lendBuffers() { return source_->lendBuffers(); }

  // Waits up to `timeout` for the next frame. kEnded once the stream has ended and its queue is
  // empty.
  Next next(FrameRef& out, std::chrono::milliseconds timeout);

  const std::string& name() const { return name_; }
  cv::Size frameSize() const { return pool_.frameSize(); }
  // What its frames are held in (as its source delivers them, or BGR).
  PixelFormat pixelFormat() const { return pool_.pixelFormat(); }
  Timestamp nominalPeriod() const { return nominalPeriod_; }
  bool repeatsOnePicture() const { return repeatsOnePicture_; }  // see FrameSource
  CameraStreamStats stats() const;
  std::size_t queued() const;  // frames waiting to be taken by next()

 private:
  void run();
  void push(FrameRef frame, std::chrono::nanoseconds readTime);

  std::string name_;
  std::unique_ptr<FrameSource> source_;
  FramePool pool_;
  // Read once: the source belongs to the capture thread once started.
  Timestamp nominalPeriod_;
  bool repeatsOnePicture_;
  RecoverySettings recovery_;

  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::vector<FrameRef> queue_;  // ring of pool capacity, preallocated
  std::size_t head_ = 0;
  std::size_t size_ = 0;
  bool ended_ = false;
  CameraStreamStats stats_;

  std::atomic<bool> stopping_{false};
  std::mutex stopMutex_;  // with stopCondition_: a backoff wait that stop() cuts short
  std::condition_variable stopCondition_;
  std::thread thread_;
};

}  // namespace surroundd::capture
