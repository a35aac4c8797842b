#pragma once
// The scene's procedural textures, generated once per recording from the seed (8-bit BGR, sides
// powers of two, seamless where they repeat).

#include <cstdint>

#include <opencv2/core.hpp>

namespace surroundd::synth {

// Asphalt (multi-octave value noise plus per-texel grain) with lane markings, parking bays and
// crosswalks painted on. Texel (col, row) covers world x = (col - size/2) * texel, y = (row -
// size/2)
// * texel.
cv::Mat makeGroundTexture(std::uint64_t seed, int size, float texelM);

// Brick facade with rows of windows; row = height above ground / texel.
cv::Mat makeFacadeTexture(std::uint64_t seed, cv::Size size, float texelM);

// Cloud density (grey, 0..255), seamless.
cv::Mat makeCloudTexture(std::uint64_t seed, int size);

}  // namespace surroundd::synth
