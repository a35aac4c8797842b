#pragma once
// The instruction sets of the per-pixel kernels (bilinear sampling, the stitcher's gather). Every
// path computes exactly the bytes the portable one does; a build uses its own machine's path
// (kNativeKernels), but compiles the portable one too, so that the tests compare them on real
// frames (tests/processing/kernel_paths_test.cpp: SSE2 on x86, any further path where it is built).

#include <array>
#include <string_view>

namespace surroundd::processing {

enum class KernelPath { kPortable, kSse2 };

#if defined(__SSE2__)
inline constexpr KernelPath kNativeKernels = KernelPath::kSse2;
inline constexpr std::array kKernelPaths = {KernelPath::kPortable, KernelPath::kSse2};
#else
inline constexpr KernelPath kNativeKernels = KernelPath::kPortable;
inline constexpr std::array kKernelPaths = {KernelPath::kPortable};
#endif

// Whether this build has `path`'s kernels.
constexpr bool kernelPathBuilt(KernelPath path) {
  for (const KernelPath built : kKernelPaths) {
    if (built == path) return true;
  }
  return false;
}

constexpr std::string_view kernelPathName(KernelPath path) {
  switch (path) {
    case KernelPath::kPortable:
      return "portable";
    case KernelPath::kSse2:
      return "sse2";
  }
  return "?";
}

}  // namespace surroundd::processing
