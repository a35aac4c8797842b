#pragma once
// Logging goes to stderr, where journald collects it when surroundd runs under systemd; FFmpeg's
// messages go the same way, in the same format.

#include <array>
#include <optional>
#include <string_view>
#include <utility>

#include <spdlog/common.h>

namespace surroundd::daemon {

// The logger for stderr at `level`, with FFmpeg's log routed into it (routeFfmpegLog()).
void setUpLogging(spdlog::level::level_enum level);
// FFmpeg's errors (a decoder's, a muxer's) become lines of the default logger, "ffmpeg: [h264 @
// 0x...] ...", at error level, or at debug where the thread expects them
// (ffmpeg::ExpectedFailures); its less than errors are dropped as before. Once, before threads.
void routeFfmpegLog();
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
