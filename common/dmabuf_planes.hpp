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
  // The buffer's name, which descriptors are not (they are reused): its driver's streaming
  // session, numbered from 1 and growing in this process, and its index there. A GPU keeps an
  // import under it, and lets the imports of a session go once a later one's buffers come.
  std::uint64_t session = 0;
  std::uint32_t index = 0;

  bool operator==(const DmabufPlanes&) const = default;
};

}  // namespace surroundd
