#include "daemon/config/logging.hpp"

#include <array>
#include <cctype>
#include <cstdarg>
#include <cstdlib>
#include <string_view>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

extern "C" {
#include <libavutil/log.h>
}

#include "common/ffmpeg_util.hpp"

namespace surroundd::daemon {
namespace {

spdlog::level::level_enum levelOf(int ffmpegLevel) {
  if (ffmpeg::ExpectedFailures::active()) return spdlog::level::debug;
  if (ffmpegLevel <= AV_LOG_ERROR) return spdlog::level::err;
  if (ffmpegLevel <= AV_LOG_WARNING) return spdlog::level::warn;
  if (ffmpegLevel <= AV_LOG_INFO) return spdlog::level::info;
  return ffmpegLevel <= AV_LOG_DEBUG ? spdlog::level::debug : spdlog::level::trace;
}

// av_log's callback; any thread (spdlog is thread-safe).
void logFfmpegLine(void* context, int level, const char* format, va_list arguments) {
  if (level > av_log_get_level()) return;
  std::array<char, 1024> line{};
  int printPrefix = 1;  // each call is a line of its own: the "[h264 @ 0x...]" context with it
  av_log_format_line2(context, level, format, arguments, line.data(), static_cast<int>(line.size()),
                      &printPrefix);
  std::string_view text(line.data());
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())) != 0) {
    text.remove_suffix(1);
  }
  if (!text.empty()) spdlog::log(levelOf(level), "ffmpeg: {}", text);
}

}  // namespace

void routeFfmpegLog() {
  // FFmpeg and x264 print statistics at info level on their own; keep only their errors.
  av_log_set_level(AV_LOG_ERROR);
  av_log_set_callback(logFfmpegLine);
}

void setUpLogging(spdlog::level::level_enum level) {
  auto logger = spdlog::stderr_color_mt("surroundd");
  // journald stamps each line itself and sets JOURNAL_STREAM for services it collects.
  // NOLINTNEXTLINE(concurrency-mt-unsafe): read once at start-up, before any thread exists.
  const bool underJournald = std::getenv("JOURNAL_STREAM") != nullptr;
  logger->set_pattern(underJournald ? "[%l] %v" : "%H:%M:%S.%e [%^%l%$] %v");
  logger->set_level(level);
  spdlog::set_default_logger(logger);
  routeFfmpegLog();
}

std::optional<spdlog::level::level_enum> parseLogLevel(std::string_view name) {
  for (const auto& [levelName, level] : kLogLevels) {
    if (levelName == name) return level;
  }
  return std::nullopt;
}

}  // namespace surroundd::daemon
