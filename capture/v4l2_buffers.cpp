#include "capture/v4l2_buffers.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <utility>

#include <linux/videodev2.h>
#include <unistd.h>

namespace surroundd::capture {

V4l2Buffers::V4l2Buffers(std::shared_ptr<V4l2Device> device, std::uint32_t type, std::size_t planes)
    : device_(std::move(device)), type_(type), planeCount_(planes) {
  static std::atomic<std::uint64_t> sessions = 0;
  session_ = ++sessions;
}

V4l2Buffers::~V4l2Buffers() {
  for (const auto& planes : buffers_) {
    for (const auto& plane : planes) {
      if (plane.dmabuf >= 0) ::close(plane.dmabuf);
      if (plane.address != nullptr) device_->unmap(plane.address, plane.length);
    }
  }
}

void V4l2Buffers::add(std::vector<Plane> planes) {
  buffers_.push_back(std::move(planes));
  lent_.push_back(0);
}

v4l2_buffer V4l2Buffers::describe(std::span<v4l2_plane> planes) const {
  v4l2_buffer buffer{};
  buffer.type = type_;
  buffer.memory = V4L2_MEMORY_MMAP;
  if (type_ == V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE) {
    buffer.m.planes = planes.data();
    buffer.length = static_cast<std::uint32_t>(planeCount_);
  }
  return buffer;
}

int V4l2Buffers::queue(v4l2_buffer& buffer) {
  const std::lock_guard lock(mutex_);
  return device_->ioctl(VIDIOC_QBUF, &buffer);
}

int V4l2Buffers::dequeue(v4l2_buffer& buffer) {
  const std::lock_guard lock(mutex_);
  return device_->ioctl(VIDIOC_DQBUF, &buffer);
}

int V4l2Buffers::startStreaming() {
  const std::lock_guard lock(mutex_);
  int type = static_cast<int>(type_);
  const int error = device_->ioctl(VIDIOC_STREAMON, &type);
  streaming_ = error == 0;
  return error;
}

void V4l2Buffers::stopStreaming() noexcept {
  const std::lock_guard lock(mutex_);
  if (!streaming_) return;
  int type = static_cast<int>(type_);
  device_->ioctl(VIDIOC_STREAMOFF, &type);
  streaming_ = false;
}

bool V4l2Buffers::lend(std::uint32_t buffer) {
  const std::lock_guard lock(mutex_);
  // This one and two more would leave the driver nothing to fill while the next is read.
  const auto lent = static_cast<std::size_t>(std::ranges::count(lent_, 1));
  if (buffer >= buffers_.size() || lent_[buffer] != 0 || lent + 3 > buffers_.size()) return false;
  lent_[buffer] = 1;
  return true;
}

void V4l2Buffers::giveBack(std::uint32_t buffer) noexcept {
  std::array<v4l2_plane, VIDEO_MAX_PLANES> planes{};
  v4l2_buffer queued = describe(planes);
  queued.index = buffer;
  const std::lock_guard lock(mutex_);
  if (buffer >= lent_.size() || lent_[buffer] == 0) return;
  lent_[buffer] = 0;
  if (!streaming_) return;
  if (const int error = device_->ioctl(VIDIOC_QBUF, &queued); error != 0) requeueError_ = error;
}

int V4l2Buffers::requeueError() {
  const std::lock_guard lock(mutex_);
  return std::exchange(requeueError_, 0);
}

}  // namespace surroundd::capture
