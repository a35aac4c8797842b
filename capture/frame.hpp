#pragma once
// A camera frame and the pool it lives in.
//
// Ownership: a FrameRef owns one pooled frame exclusively (unique_ptr semantics). Moving it hands
// the frame down the pipeline; destroying it returns the buffer to its pool, so nothing is
// allocated per frame once a pool is built. The pool's shared state is kept alive by every
// outstanding FrameRef, so a frame may outlive the source that produced it.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include <opencv2/core.hpp>

#include "common/pixel_format.hpp"

namespace surroundd::capture {

// Timestamps are on the source's monotonic clock (the driver's, or the file's presentation time),
// in nanoseconds.
using Timestamp = std::chrono::nanoseconds;

struct Frame {
  // The picture as `format` holds it (common/pixel_format.hpp: BGR, or the camera's own YUYV or
  // NV12), allocated once by the pool; never reallocated per frame.
  cv::Mat image;
  PixelFormat format = PixelFormat::kBgr;
  Timestamp timestamp{0};      // presentation (capture) time of the first pixel row
  std::uint64_t sequence = 0;  // per-source frame counter; gaps mean the source skipped frames
  // Decoded with errors that the decoder concealed (the source's lastError() says which): shown,
  // and counted as a fault.
  bool concealedErrors = false;
  // When its source handed it over (set by CameraStream): where a replayed frame's latency starts.
  std::chrono::steady_clock::time_point arrival{};
};

class FramePool;

namespace detail {
struct FramePoolState;
struct FrameReturner {
  std::shared_ptr<FramePoolState> pool;
  void operator()(Frame* frame) const noexcept;
};
}  // namespace detail

using FrameRef = std::unique_ptr<Frame, detail::FrameReturner>;

// A fixed set of preallocated frames of one size and format. acquire() blocks while all are in
// use, which is how a consumer that falls behind applies back-pressure to a replay source.
class FramePool {
 public:
  FramePool(std::size_t count, cv::Size size, PixelFormat format = PixelFormat::kBgr);

  // Blocks until a frame is free or `timeout` passes; returns an empty FrameRef on timeout.
  FrameRef acquire(std::chrono::milliseconds timeout);
  FrameRef tryAcquire();

  cv::Size frameSize() const { return size_; }
  PixelFormat pixelFormat() const { return format_; }
  std::size_t capacity() const;
  std::size_t available() const;

 private:
  FrameRef take(std::unique_lock<std::mutex>& lock);

  std::shared_ptr<detail::FramePoolState> state_;
  cv::Size size_;
  PixelFormat format_;
};

}  // namespace surroundd::capture
