#pragma once
// The most cameras one rig may have: the one camera-count limit of surroundd. Every other bound on
// a camera count (the config's rig list, the synchronizer's fixed slots, the panorama LUT's camera
// byte, colour correction's camera bitmask) is this one, or is checked against it where it is
// defined.

#include <cstddef>

namespace surroundd {

// Fixed so that a frame set and the synchronizer's per-camera state never allocate; eight covers a
// car's four plus a truck's or trailer's extra cameras.
inline constexpr std::size_t kMaxCameras = 8;

}  // namespace surroundd
