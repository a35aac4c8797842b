#pragma once
// One camera's H.264 encoder on a thread of its own, fed through a small ring of preallocated
// frames: rendering the next frame overlaps encoding the previous ones, and four cameras encode
// in parallel.
//
// Ownership: the worker owns the ring. acquire() lends the next free slot to the renderer until
// submit() hands it to the encoder thread. An encoder error is kept and rethrown on the caller's
// thread by the next acquire()/submit()/finish(); nothing is thrown across threads.

#include <chrono>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

#include "render/outputs/video_encoder.hpp"

namespace surroundd::synth {

class EncodeWorker {
 public:
  EncodeWorker(render::VideoEncoderSettings settings, int depth = 3);
  ~EncodeWorker();
  EncodeWorker(const EncodeWorker&) = delete;
  EncodeWorker& operator=(const EncodeWorker&) = delete;

  // Blocks until a slot is free; the returned image (CV_8UC3, the video's size) is the caller's
  // until submit().
  cv::Mat& acquire();
  void submit(std::chrono::nanoseconds timestamp);
  // Encodes what is queued, finalizes the file and joins the thread.
  void finish();

 private:
  struct Slot {
    cv::Mat image;
    std::chrono::nanoseconds timestamp{0};
  };
  void run();
  void rethrowIfFailed();

  render::VideoEncoderSettings settings_;
  std::vector<Slot> slots_;
  std::size_t head_ = 0;  // next slot to fill (caller)
  std::size_t tail_ = 0;  // next slot to encode (worker)
  std::size_t queued_ = 0;
  bool closing_ = false;
  std::exception_ptr error_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::thread thread_;
};

}  // namespace surroundd::synth
