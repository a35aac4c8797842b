#pragma once
// A camera frame and the pool it lives in.
//
// Ownership: a FrameRef owns one pooled frame exclusively (unique_ptr semantics). Moving it hands
// the frame down the pipeline; destroying it returns the buffer to its pool, so nothing is
// allocated per frame once a pool is built. The pool's shared state is kept alive by every
// outstanding FrameRef, so a frame may outlive the source that produced it.
//
// A source may lend a frame its driver's buffer instead of copying into the frame's own picture
// (V4l2Source::lendBuffers): then `image` views that buffer, `dmabuf` says where a GPU can import
// it, and the buffer goes back to its driver when the frame goes back to its pool.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include <opencv2/core.hpp>

#include "common/dmabuf_planes.hpp"
#include "common/pixel_format.hpp"

namespace surroundd::capture {

// Timestamps are on the source's monotonic clock (the driver's, or the file's presentation time),
// in nanoseconds.
using Timestamp = std::chrono::nanoseconds;

// Takes back a buffer it lent to a frame, when the frame is returned (on the thread that returns
// it, so safe to call from any).
class BufferLender {
 public:
  virtual ~BufferLender() = default;
  BufferLender() = default;
  BufferLender(const BufferLender&) = delete;
  BufferLender& operator=(const BufferLender&) = delete;
  virtual void giveBack(std::uint32_t buffer) noexcept = 0;
};

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
  // Set while `image` views a lent driver buffer (planes == 0 otherwise).
  DmabufPlanes dmabuf;
  struct Loan {
    std::shared_ptr<BufferLender> lender;  // null: nothing lent
    std::uint32_t buffer = 0;
    cv::Mat own;  // the frame's own picture, back in `image` when the loan ends
  } loan;
};

// Ends a frame's loan, if it has one: its own picture back in `image`, the buffer back to its
// lender. Allocates nothing. Returning a frame to its pool does this.
void endLoan(Frame& frame) noexcept;

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
