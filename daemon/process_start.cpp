#include "daemon/process_start.hpp"

#include <ctime>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include <unistd.h>

namespace surroundd::daemon {
namespace {

using Clock = std::chrono::steady_clock;

// Field 22 of /proc/self/stat: clock ticks from boot to the process's start. The second field,
// the command name in parentheses, may hold spaces, so the fields are counted after its ')'.
std::optional<long long> startTicksSinceBoot() {
  std::ifstream file("/proc/self/stat");
  std::string stat;
  if (!std::getline(file, stat)) return std::nullopt;
  const auto nameEnd = stat.rfind(')');
  if (nameEnd == std::string::npos) return std::nullopt;
  std::istringstream fields(stat.substr(nameEnd + 1));
  std::string field;
  for (int index = 3; index < 22; ++index) fields >> field;  // state (3) .. itrealvalue (21)
  long long ticks = 0;
  if (!(fields >> ticks)) return std::nullopt;
  return ticks;
}

std::chrono::nanoseconds sinceBoot() {
  timespec now{};
  clock_gettime(CLOCK_BOOTTIME, &now);
  return std::chrono::seconds(now.tv_sec) + std::chrono::nanoseconds(now.tv_nsec);
}

}  // namespace

std::chrono::steady_clock::time_point processStartTime() {
  const auto steadyNow = Clock::now();
  const auto ticks = startTicksSinceBoot();
  const long ticksPerSecond = sysconf(_SC_CLK_TCK);
  if (!ticks || ticksPerSecond <= 0) return steadyNow;
  // The start is on CLOCK_BOOTTIME, the steady clock is CLOCK_MONOTONIC; they differ by the time
  // the machine was suspended, which does not change between the start and now.
  const std::chrono::nanoseconds started{*ticks * 1'000'000'000LL / ticksPerSecond};
  const auto age = sinceBoot() - started;
  return age > Clock::duration::zero() ? steadyNow - age : steadyNow;
}

}  // namespace surroundd::daemon
