#pragma once
// Four floats (or two doubles) per operation, through the GCC/Clang vector extensions, for the
// Poisson solvers' loops over grid rows and the correction's three channels of a pixel. The project
// builds with -O2, where GCC 12 does not vectorize loops; these lower to SSE2 on x86-64 and NEON on
// AArch64 from one source, with the same results on both: each lane is rounded as the scalar
// operation is, and -ffp-contract=off (CMakeLists.txt) keeps AArch64 from fusing a * b + c. Loads
// and stores go through memcpy: any alignment, no aliasing questions.

#include <algorithm>
#include <cstdint>
#include <cstring>

namespace surroundd::processing {

using FloatLanes = float __attribute__((vector_size(16)));
using DoubleLanes = double __attribute__((vector_size(16)));
inline constexpr int kFloatLanes = 4;
inline constexpr int kDoubleLanes = 2;

inline FloatLanes loadLanes(const float* p) {
  FloatLanes v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline DoubleLanes loadLanes(const double* p) {
  DoubleLanes v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
// Two floats from p, as doubles; and two doubles stored as floats.
using FloatPair = float __attribute__((vector_size(8)));
inline DoubleLanes loadWidened(const float* p) {
  FloatPair v;
  std::memcpy(&v, p, sizeof v);
  return __builtin_convertvector(v, DoubleLanes);
}
inline void storeNarrowed(float* p, DoubleLanes v) {
  const FloatPair narrow = __builtin_convertvector(v, FloatPair);
  std::memcpy(p, &narrow, sizeof narrow);
}
inline void storeLanes(float* p, FloatLanes v) { std::memcpy(p, &v, sizeof v); }

using IntLanes = std::int32_t __attribute__((vector_size(16)));
// Each lane truncated toward zero, as a cast of one float is.
inline IntLanes truncatedLanes(FloatLanes v) { return __builtin_convertvector(v, IntLanes); }

// std::clamp of each lane, and of one float: the same comparisons, so the same results.
inline float clampLanes(float v, float low, float high) { return std::clamp(v, low, high); }
inline FloatLanes clampLanes(FloatLanes v, float low, float high) {
  const FloatLanes lows = {low, low, low, low};
  const FloatLanes highs = {high, high, high, high};
  return v < lows ? lows : (highs < v ? highs : v);
}
inline void storeLanes(double* p, DoubleLanes v) { std::memcpy(p, &v, sizeof v); }

}  // namespace surroundd::processing
