#pragma once
// The driver buffers of one V4L2 streaming session (V4l2Source's): mapped, exported as DMABUFs
// where the driver can, and lent to frames (capture/frame.hpp). A lent buffer is given back on
// whatever thread lets its frame go, so every queue, dequeue and stream-off of the session goes
// through here under one lock. Once the session has stopped, a buffer given back stays out of the
// driver; the mappings and exports go when the source and the last frame lent one are done.

#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include "capture/frame.hpp"
#include "capture/v4l2_device.hpp"

struct v4l2_buffer;
struct v4l2_plane;

namespace surroundd::capture {

class V4l2Buffers final : public BufferLender {
 public:
  struct Plane {
    void* address = nullptr;
    std::size_t length = 0;
    int dmabuf = -1;  // the plane exported (VIDIOC_EXPBUF), or -1
  };

  // `type`: V4L2_BUF_TYPE_VIDEO_CAPTURE or ..._MPLANE; `planes`: each buffer's.
  V4l2Buffers(std::shared_ptr<V4l2Device> device, std::uint32_t type, std::size_t planes);
  ~V4l2Buffers() override;  // unmaps, closes the exports

  // Set-up, before streaming.
  void add(std::vector<Plane> planes);
  std::span<const Plane> planes(std::uint32_t buffer) const { return buffers_[buffer]; }
  std::size_t count() const { return buffers_.size(); }
  // This process's streaming sessions, numbered from 1 (DmabufPlanes::session).
  std::uint64_t session() const { return session_; }
  // A buffer of the session's type for QUERYBUF, QBUF and DQBUF; a multi-planar one points at
  // `planes` for its per-plane fields.
  v4l2_buffer describe(std::span<v4l2_plane> planes) const;

  // VIDIOC_QBUF, DQBUF, STREAMON and STREAMOFF under the lock; 0 or the errno.
  int queue(v4l2_buffer& buffer);
  int dequeue(v4l2_buffer& buffer);
  int startStreaming();
  void stopStreaming() noexcept;

  // Marks dequeued `buffer` lent when at least two others stay with the driver (so that it always
  // has one to fill while the next is read); false, and nothing lent, otherwise.
  bool lend(std::uint32_t buffer);
  // Queues it again while the session streams; a buffer not lent is left alone (a frame given
  // back twice must not queue it twice). A refusal is kept for requeueError().
  void giveBack(std::uint32_t buffer) noexcept override;
  // The errno of a give-back the driver refused since the last call, or 0.
  int requeueError();

 private:
  std::shared_ptr<V4l2Device> device_;
  std::uint64_t session_;  // this process's streaming sessions, counted from 1
  std::uint32_t type_;
  std::size_t planeCount_;
  std::vector<std::vector<Plane>> buffers_;
  std::mutex mutex_;  // the device's streaming calls, and what follows, from any thread
  bool streaming_ = false;
  std::vector<char> lent_;  // per buffer
  int requeueError_ = 0;
};

}  // namespace surroundd::capture
