#pragma once
// One recovery policy for every camera source kind (V4L2, libcamera, file replay), and one
// rate-limited log of its faults.
//
// A source reports what went wrong; the policy decides what happens next, the same way for all:
//   - every fault is counted: a lost frame (kFault), a frame decoded with concealed errors, a lost
//     device (kLost), a failed reopening;
//   - a lost device is reopened after a backoff that starts at firstBackoff and doubles up to
//     maxBackoff; it goes back to firstBackoff once a frame comes through again (a device that
//     opens and then delivers nothing keeps backing off);
//   - after giveUpAfterFaults faults in a row without a frame the camera is given up (its stream
//     ends); 0, the default, keeps trying for as long as the service runs;
//   - faults are logged through a FaultLog: the first in full, then at most one line per
//     logInterval that counts what was left out (a corrupt MJPEG stream at 30 faults a second logs
//     one line every 10 s, not 30 a second).
//
// Threads: a SourceRecovery belongs to the thread that reads its source (a CameraStream's capture
// thread); it is not shared.

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "capture/frame_source.hpp"

namespace surroundd::capture {

struct RecoverySettings {
  std::chrono::milliseconds firstBackoff{100};  // reopening a lost device: the first wait
  std::chrono::milliseconds maxBackoff{2000};   // ... doubled each failed try, up to this
  int giveUpAfterFaults = 0;  // faults in a row (no frame between) that end the camera; 0: never
  std::chrono::milliseconds logInterval{
      10'000};  // repeated faults: one log line at most this often
  bool operator==(const RecoverySettings&) const = default;
};

// A camera's faults in the log, rate-limited: the first in a quiet period is logged in full (at
// warning level); the ones after it within `interval` are only counted, and the first fault after
// the interval logs one line with that count and its own message. flush() logs what is still
// counted (at the end of the stream, or once frames flow again after the interval).
class FaultLog {
 public:
  using Clock = std::chrono::steady_clock;
  FaultLog(std::string camera, std::chrono::milliseconds interval);

  void fault(std::string_view message, Clock::time_point now);
  // A recovery worth knowing (a device reopened), at info level; counted like a fault while the
  // log holds back lines.
  void note(std::string_view message, Clock::time_point now);
  void flush(Clock::time_point now);
  void flushIfDue(Clock::time_point now);  // flush() once the interval is over

  std::uint64_t linesLogged() const { return lines_; }
  std::uint64_t linesLeftOut() const { return leftOut_; }

 private:
  bool holdingBack(Clock::time_point now) const;
  void summary(Clock::time_point now, std::string_view latest);

  std::string camera_;
  std::chrono::milliseconds interval_;
  std::optional<Clock::time_point> windowStart_;  // of the last line logged
  std::uint64_t heldFaults_ = 0;                  // left out since windowStart_
  std::uint64_t heldNotes_ = 0;
  std::string lastHeld_;
  std::uint64_t lines_ = 0;
  std::uint64_t leftOut_ = 0;
};

class SourceRecovery {
 public:
  using Clock = std::chrono::steady_clock;
  // Waits for `duration` unless the reader is asked to stop; false when it was.
  using Wait = std::function<bool(std::chrono::milliseconds duration)>;

  SourceRecovery(std::string camera, RecoverySettings settings);

  // One read under the policy: reopens a lost source (after the backoff, through `wait`) before
  // reading it. kFrame: `out` holds a frame (perhaps one with concealed errors, counted as a
  // fault); kFault: no frame this time, call again; kEndOfStream: the source ended, the policy gave
  // up on it, or `wait` said stop. Never throws.
  ReadStatus read(FrameSource& source, Frame& out, const Wait& wait);

  // The policy's steps, for read() and for tests that drive them with their own clock.
  enum class Step { kReadAgain, kReopen, kGiveUp };
  Step onFault(std::string_view message, bool lost, Clock::time_point now);
  void onFrame(Clock::time_point now);
  void onReopened(Clock::time_point now);
  void onEnd(Clock::time_point now);
  std::chrono::milliseconds backoff() const { return backoff_; }  // before the next reopening

  std::uint64_t faults() const { return faults_; }
  std::uint64_t reopens() const { return reopens_; }
  bool gaveUp() const { return gaveUp_; }
  const FaultLog& log() const { return log_; }

 private:
  std::string camera_;
  RecoverySettings settings_;
  FaultLog log_;
  std::chrono::milliseconds backoff_{0};
  bool lost_ = false;  // the source is closed and waits to be reopened
  bool gaveUp_ = false;
  int inARow_ = 0;
  std::uint64_t faults_ = 0;
  std::uint64_t reopens_ = 0;
};

}  // namespace surroundd::capture
