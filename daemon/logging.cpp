#include "daemon/logging.hpp"

#include <cstdlib>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

extern "C" {
#include <libavutil/log.h>
}

namespace surroundd::daemon {

void setUpLogging(spdlog::level::level_enum level) {
  auto logger = spdlog::stderr_color_mt("surroundd");
  // journald stamps each line itself and sets JOURNAL_STREAM for services it collects.
  // NOLINTNEXTLINE(concurrency-mt-unsafe): read once at start-up, before any thread exists.
  const bool underJournald = std::getenv("JOURNAL_STREAM") != nullptr;
  logger->set_pattern(underJournald ? "[%l] %v" : "%H:%M:%S.%e [%^%l%$] %v");
  logger->set_level(level);
  spdlog::set_default_logger(logger);
  // FFmpeg and x264 print statistics at info level on their own; keep only their errors.
  av_log_set_level(AV_LOG_ERROR);
}

std::optional<spdlog::level::level_enum> parseLogLevel(std::string_view name) {
  for (const auto& [levelName, level] : kLogLevels) {
    if (levelName == name) return level;
  }
  return std::nullopt;
}

}  // namespace surroundd::daemon
