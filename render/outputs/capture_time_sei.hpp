#pragma once
// The capture time a live H.264 stream carries with each picture, so that a viewer can measure how
// late it shows what the cameras saw (capture to screen, across machines whose clocks agree).
//
// It is an H.264 "user data unregistered" SEI message (ITU-T H.264 D.1.7, payload type 5) in the
// picture's access unit: the 16-byte UUID below, then the microseconds since 1970-01-01 UTC as a
// big-endian signed 64-bit integer — 24 bytes in all. Decoders that do not know it skip it;
// FFmpeg's H.264 decoder hands it over as the frame's AV_FRAME_DATA_SEI_UNREGISTERED side data.

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <span>

namespace surroundd::render {

inline constexpr std::array<std::uint8_t, 16> kCaptureTimeSeiUuid{
    0xd8, 0x54, 0xe2, 0xa6, 0x39, 0xb0, 0x4b, 0x84, 0xa3, 0x92, 0x86, 0xda, 0xed, 0xa6, 0x42, 0xf5};

using CaptureTimeSei = std::array<std::uint8_t, kCaptureTimeSeiUuid.size() + 8>;

inline CaptureTimeSei captureTimeSei(std::chrono::system_clock::time_point captured) {
  CaptureTimeSei payload{};
  const auto micros = static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::microseconds>(captured.time_since_epoch()).count());
  for (std::size_t i = 0; i < kCaptureTimeSeiUuid.size(); ++i) payload[i] = kCaptureTimeSeiUuid[i];
  for (std::size_t i = 0; i < 8; ++i) {
    payload[kCaptureTimeSeiUuid.size() + i] = static_cast<std::uint8_t>(micros >> (56 - 8 * i));
  }
  return payload;
}

// The capture time in an SEI payload (the UUID and what follows), or none if it is not ours.
inline std::optional<std::chrono::system_clock::time_point> captureTimeFromSei(
    std::span<const std::uint8_t> payload) {
  if (payload.size() != CaptureTimeSei{}.size()) return std::nullopt;
  for (std::size_t i = 0; i < kCaptureTimeSeiUuid.size(); ++i) {
    if (payload[i] != kCaptureTimeSeiUuid[i]) return std::nullopt;
  }
  std::uint64_t micros = 0;
  for (std::size_t i = 0; i < 8; ++i)
    micros = (micros << 8) | payload[kCaptureTimeSeiUuid.size() + i];
  return std::chrono::system_clock::time_point(
      std::chrono::duration_cast<std::chrono::system_clock::duration>(
          std::chrono::microseconds(static_cast<std::int64_t>(micros))));
}

}  // namespace surroundd::render
