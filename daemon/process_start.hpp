#pragma once
// When this process started, on the steady clock, for the start-up figure (the time from the
// process's start to its first picture out; pipeline_report.hpp).

#include <chrono>

namespace surroundd::daemon {

// The kernel's record of the process's start (/proc/self/stat), not a clock read in main, so that
// what happens before main counts too: the exec, the dynamic loader mapping OpenCV, FFmpeg and
// Mesa, static initializers — and under systemd, the unit's set-up between its fork and the exec
// (the kernel stamps the fork). A driver waits for all of it. Precise to one clock tick (10 ms),
// rounded down, so the start-up figure errs long, never short. Where /proc cannot be read: now,
// so call it first thing in main.
std::chrono::steady_clock::time_point processStartTime();

}  // namespace surroundd::daemon
