#pragma once
// Where a picture lies in buffers a driver exported as DMABUF file descriptors, for a GPU to import
// without a copy: one plane (YUYV, UYVY) or two (NV12's luma and chroma, in one buffer or two).

#include <array>
#include <cstdint>

namespace surroundd {

struct DmabufPlanes {
  std::uint32_t planes = 0;  // 0: in no DMABUF
  std::array<int, 2> fd{-1, -1};
  std::array<std::uint32_t, 2> offset{};  // bytes from the buffer's start
  std::array<std::uint32_t, 2> pitch{};   // bytes a line
  // Names the buffer while it exists and is never given to another (descriptors are reused): what
  // a GPU keeps an import under.
  std::uint64_t buffer = 0;
};

}  // namespace surroundd
