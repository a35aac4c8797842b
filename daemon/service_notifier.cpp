#include "daemon/service_notifier.hpp"

#include <fmt/format.h>
#include <systemd/sd-daemon.h>

namespace surroundd::daemon {

ServiceNotifier::ServiceNotifier(std::optional<std::chrono::microseconds> watchdog, Send send)
    : watchdog_(watchdog), send_(std::move(send)) {}

ServiceNotifier ServiceNotifier::fromEnvironment() {
  std::uint64_t usec = 0;
  std::optional<std::chrono::microseconds> watchdog;
  if (sd_watchdog_enabled(0, &usec) > 0) watchdog = std::chrono::microseconds(usec);
  return ServiceNotifier(
      watchdog, [](std::string_view message) { sd_notify(0, std::string(message).c_str()); });
}

void ServiceNotifier::tick(Clock::time_point now, std::uint64_t frameSets, bool outputsWork) {
  if (frameSets == 0) return;  // nothing has come through yet: not ready, nothing to ping for
  if (!ready_) {
    ready_ = true;
    send_("READY=1");
    nextStatus_ = now;
  }
  if (watchdog_ && outputsWork && now >= nextPing_ && frameSets > pingedAt_) {
    send_("WATCHDOG=1");
    pingedAt_ = frameSets;
    nextPing_ = now + *watchdog_ / 2;
  }
}

void ServiceNotifier::status(Clock::time_point now, std::string_view text) {
  send_(fmt::format("STATUS={}", text));
  nextStatus_ = now + kStatusInterval;
}

void ServiceNotifier::reloading() {
  send_("RELOADING=1\nSTATUS=reloading the config");
  ready_ = false;
  pingedAt_ = 0;  // the new pipeline counts its frame sets from zero
}

void ServiceNotifier::stopping() { send_("STOPPING=1\nSTATUS=finalizing the outputs"); }

}  // namespace surroundd::daemon
