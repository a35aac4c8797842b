#pragma once
// The only way V4L2 code reaches the kernel: open, ioctl, mmap, poll on one video node. The
// kernel's implementation is makeKernelV4l2Device(); tests stand an in-process fake device in its
// place to exercise negotiation, streaming and faults without hardware.
//
// Every call returns 0 on success or an errno value (never throws), as the kernel does.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace surroundd::capture {

class V4l2Device {
 public:
  virtual ~V4l2Device() = default;
  V4l2Device() = default;
  V4l2Device(const V4l2Device&) = delete;
  V4l2Device& operator=(const V4l2Device&) = delete;

  virtual int open(const std::string& path) = 0;  // read-write, non-blocking
  virtual void close() = 0;                       // also unmaps nothing: unmap() first
  virtual int ioctl(unsigned long request, void* argument) = 0;
  // Maps `length` bytes of the device at `offset` (from VIDIOC_QUERYBUF); nullptr on failure.
  virtual void* map(std::size_t length, std::int64_t offset) = 0;
  virtual void unmap(void* address, std::size_t length) = 0;
  // Waits until a buffer can be dequeued: 0 ready, ETIMEDOUT, or the error (ENODEV when the device
  // is gone).
  virtual int waitReadable(std::chrono::milliseconds timeout) = 0;
};

std::unique_ptr<V4l2Device> makeKernelV4l2Device();

}  // namespace surroundd::capture
