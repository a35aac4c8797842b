#pragma once
// The instruction sets of the per-pixel kernels (bilinear sampling, the stitcher's gather). Every
// path computes exactly the bytes the portable one does; a build uses its own machine's path
// (kNativeKernels), but compiles the portable one too, so that the tests compare them on real
// frames (tests/processing/stitch/kernel_paths_test.cpp: SSE2 on x86-64, NEON on arm64).

#include <array>
#include <string_view>

namespace surroundd::processing {

enum class KernelPath { kPortable, kSse2, kNeon };

#if defined(__SSE2__)
inline constexpr KernelPath kNativeKernels = KernelPath::kSse2;
inline constexpr std::array kKernelPaths = {KernelPath::kPortable, KernelPath::kSse2};
#elif defined(__ARM_NEON)
inline constexpr KernelPath kNativeKernels = KernelPath::kNeon;
inline constexpr std::array kKernelPaths = {KernelPath::kPortable, KernelPath::kNeon};
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
    case KernelPath::kNeon:
      return "neon";
  }
  return "?";
}

}  // namespace surroundd::processing
