#pragma once
// Logging goes to stderr, where journald collects it when surroundd runs under systemd.

#include <array>
#include <optional>
#include <string_view>
#include <utility>

#include <spdlog/common.h>

namespace surroundd::daemon {

void setUpLogging(spdlog::level::level_enum level);
// The names of logging.level and --log-level.
inline constexpr std::array<std::pair<std::string_view, spdlog::level::level_enum>, 6> kLogLevels{{
    {"trace", spdlog::level::trace},
    {"debug", spdlog::level::debug},
    {"info", spdlog::level::info},
    {"warning", spdlog::level::warn},
    {"error", spdlog::level::err},
    {"off", spdlog::level::off},
}};
std::optional<spdlog::level::level_enum> parseLogLevel(std::string_view name);

}  // namespace surroundd::daemon
