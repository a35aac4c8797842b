#pragma once
// What systemd hears from surroundd (Type=notify): READY=1 once the first frame set has gone
// through the pipeline; STATUS= with the frame rate and each camera's health, every few seconds;
// WATCHDOG=1 every half watchdog interval (WatchdogSec=), but only when frame sets came through
// since the last ping: a stalled pipeline stops pinging and systemd restarts it.
//
// Without systemd (no NOTIFY_SOCKET) sd_notify does nothing, so the daemon runs the same.
// Threads: used by the pipeline thread only.

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace surroundd::daemon {

class ServiceNotifier {
 public:
  using Clock = std::chrono::steady_clock;
  using Send = std::function<void(std::string_view message)>;

  // `watchdog`: WatchdogSec, when systemd set one (WATCHDOG_USEC); `send` defaults to sd_notify.
  ServiceNotifier(std::optional<std::chrono::microseconds> watchdog, Send send);
  // From the environment systemd gives the service.
  static ServiceNotifier fromEnvironment();

  // Called by the pipeline thread as it loops (at least every few hundred milliseconds, stalled
  // or not), with the frame sets so far; the watchdog is fed only while sets come and some output
  // works.
  void tick(Clock::time_point now, std::uint64_t frameSets, bool outputsWork = true);
  // Whether a new status line is due (the caller then makes one and hands it to status()).
  bool statusDue(Clock::time_point now) const { return ready_ && now >= nextStatus_; }
  void status(Clock::time_point now, std::string_view text);
  // Before finalizing the outputs on the way out.
  void stopping();
  // Before finalizing the outputs for a reload; READY=1 follows with the new pipeline's first set.
  void reloading();

  static constexpr std::chrono::seconds kStatusInterval{2};

 private:
  std::optional<std::chrono::microseconds> watchdog_;
  Send send_;
  bool ready_ = false;
  std::uint64_t pingedAt_ = 0;  // frame sets at the last ping
  Clock::time_point nextPing_{};
  Clock::time_point nextStatus_{};
};

}  // namespace surroundd::daemon
