#pragma once
// Counter-based randomness: every random number the generator draws is a pure function of
// (seed, stream, counters), so a frame's pixels do not depend on thread scheduling or on how many
// numbers were drawn before them, and any part of a recording can be reproduced on its own.

#include <cstdint>
#include <string_view>

namespace surroundd::synth {

// splitmix64's finalizer: a bijective 64-bit mix with full avalanche.
constexpr std::uint64_t mix64(std::uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return x;
}

constexpr std::uint64_t hash64(std::uint64_t a, std::uint64_t b = 0, std::uint64_t c = 0,
                               std::uint64_t d = 0) {
  std::uint64_t h = mix64(a + 0x9e3779b97f4a7c15ULL);
  h = mix64(h ^ (b + 0x632be59bd9b4e019ULL));
  h = mix64(h ^ (c + 0x85157af5ULL));
  return mix64(h ^ d);
}

// Uniform in [0, 1) from the top 53 bits.
constexpr double unitFromHash(std::uint64_t h) {
  return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0);
}

// A deterministic stream of uniforms for set-up code (scene layout, camera parameters).
//
// One draw per statement, never two in one call's arguments: C++ leaves the order of a call's
// arguments open (GCC takes them right to left on x86-64, left to right on arm64), and an arm64
// build drew other colours for the same scene. Where draws were once arguments of one call, they
// are now made one by one in the order x86-64 took, so every recording stays as it was.
class HashRng {
 public:
  constexpr HashRng(std::uint64_t seed, std::uint64_t stream) : seed_(seed), stream_(stream) {}
  double uniform(double lo, double hi) { return lo + (hi - lo) * unitFromHash(next()); }
  int integer(int lo, int hiInclusive) {
    return lo + static_cast<int>(next() % static_cast<std::uint64_t>(hiInclusive - lo + 1));
  }
  std::uint64_t next() { return hash64(seed_, stream_, counter_++); }

 private:
  std::uint64_t seed_;
  std::uint64_t stream_;
  std::uint64_t counter_ = 0;
};

// FNV-1a, for the recording cache key (not security relevant: it only detects changed inputs).
constexpr std::uint64_t fnv1a(std::string_view text, std::uint64_t h = 0xcbf29ce484222325ULL) {
  for (const char ch : text) {
    h ^= static_cast<unsigned char>(ch);
    h *= 0x100000001b3ULL;
  }
  return h;
}

}  // namespace surroundd::synth
