#pragma once
// The limits a surround view's figures are held to, in one place; the status, the metrics and the
// benchmark print each figure beside its limit (pipeline_report.hpp).
//
// - Frame rate and latency: ISO 16505:2019 (camera monitor systems), whose figures IEC 63033-3
//   asks of a surround view system: at least 30 frames per second, and less than 200 ms from a
//   scene's capture to its picture on the display. surroundd holds its capture-to-output p99 to it.
// - The first picture: FMVSS 111 (49 CFR 571.111, rear visibility) wants the rear view shown within
//   2.0 s of the start of a backing event; surroundd's own target is 1 s with a warm LUT cache, so
//   that a daemon started with the vehicle (or restarted) is in time with room to spare.
// - A switch of view (reverse gear's rule, `surroundctl view`): held to the same 2.0 s from the
//   request to the new view settled on screen, transition included; surroundd's target is 0.5 s.

#include <chrono>

namespace surroundd::daemon::limits {

inline constexpr const char* kFrameRateAndLatencyStandard = "ISO 16505 / IEC 63033-3";
inline constexpr double kMinFramesPerSecond = 30.0;           // at least
inline constexpr std::chrono::milliseconds kMaxLatency{200};  // strictly less, at the p99

inline constexpr const char* kFirstPictureStandard = "FMVSS 111";
inline constexpr std::chrono::milliseconds kMaxFirstPicture{2000};     // at most
inline constexpr std::chrono::milliseconds kFirstPictureTarget{1000};  // surroundd's, warm cache
inline constexpr std::chrono::milliseconds kViewSwitchTarget{500};     // surroundd's, settled

constexpr bool frameRateMet(double framesPerSecond) {
  return framesPerSecond >= kMinFramesPerSecond;
}
constexpr bool latencyMet(std::chrono::nanoseconds p99) { return p99 < kMaxLatency; }
constexpr bool firstPictureMet(std::chrono::nanoseconds startup) {
  return startup <= kMaxFirstPicture;
}
constexpr bool firstPictureTargetMet(std::chrono::nanoseconds startup) {
  return startup <= kFirstPictureTarget;
}
constexpr bool viewSwitchTargetMet(std::chrono::nanoseconds settled) {
  return settled <= kViewSwitchTarget;
}

}  // namespace surroundd::daemon::limits
