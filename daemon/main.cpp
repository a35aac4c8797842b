// surroundd: replays (later: captures) four cameras and writes the configured outputs.
//
// Exit codes: 0 done, 1 failed at run time or start-up (a camera or output could not be opened),
// 2 bad command line or config (nothing was opened).

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string_view>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "daemon/config.hpp"
#include "daemon/logging.hpp"
#include "daemon/pipeline.hpp"

namespace {

using namespace surroundd;

constexpr std::string_view kUsage =
    R"(usage: surroundd --config FILE [--log-level LEVEL] [--pacing MODE] [--check-config]

  --config FILE       the YAML config (see config/surroundd.reference.yaml)
  --check-config      check the config, say what is wrong (exit 2) or that it is good (exit 0),
                      and open nothing
  --log-level LEVEL   trace, debug, info, warning, error or off; overrides logging.level
  --pacing MODE       realtime or as_fast_as_possible; overrides capture.pacing
  --help              this text
)";

// Set from the signal handler; a lock-free atomic is async-signal-safe.
std::atomic<bool> stopRequested{false};
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void requestStop(int /*signal*/) { stopRequested = true; }

void installSignalHandlers() {
  struct sigaction action {};
  action.sa_handler = requestStop;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

struct Arguments {
  std::string configFile;
  std::optional<spdlog::level::level_enum> logLevel;
  std::optional<capture::Pacing> pacing;
  bool checkOnly = false;
};

// nullopt after printing what was wrong (or the help text, with `help` set).
std::optional<Arguments> parseArguments(int argc, char** argv, bool& help) {
  Arguments arguments;
  const auto fail = [](std::string_view message) {
    fmt::print(stderr, "surroundd: {}\n{}", message, kUsage);
    return std::nullopt;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string_view flag = argv[i];
    if (flag == "--help" || flag == "-h") {
      help = true;
      fmt::print("{}", kUsage);
      return std::nullopt;
    }
    if (flag == "--check-config") {
      arguments.checkOnly = true;
      continue;
    }
    if (i + 1 >= argc) return fail(fmt::format("'{}' needs a value", flag));
    const std::string_view value = argv[++i];
    if (flag == "--config") {
      arguments.configFile = value;
    } else if (flag == "--log-level") {
      arguments.logLevel = daemon::parseLogLevel(value);
      if (!arguments.logLevel) return fail(fmt::format("unknown log level '{}'", value));
    } else if (flag == "--pacing") {
      if (value == "realtime") {
        arguments.pacing = capture::Pacing::kRealtime;
      } else if (value == "as_fast_as_possible") {
        arguments.pacing = capture::Pacing::kAsFastAsPossible;
      } else {
        return fail(fmt::format("unknown pacing '{}'", value));
      }
    } else {
      return fail(fmt::format("unknown option '{}'", flag));
    }
  }
  if (arguments.configFile.empty()) return fail("--config is required");
  return arguments;
}

void logSummary(const daemon::RunSummary& summary) {
  spdlog::info(
      "{} frame sets in {:.2f} s: {:.1f} fps; sync dropped {} frames, max spread {:.2f} ms",
      summary.frameSets, summary.wallTime.count(), summary.framesPerSecond(),
      summary.sync.totalDropped(),
      std::chrono::duration<double, std::milli>(summary.sync.maxSpread).count());
  for (std::size_t c = 0; c < summary.cameras.size(); ++c) {
    spdlog::info(
        "camera '{}': {} frames, {} faults, {} dropped unmatched, {} out of order, {} sets sent "
        "without it",
        summary.cameraNames[c], summary.cameras[c].frames, summary.cameras[c].faults,
        summary.sync.unmatchedDropped[c], summary.sync.outOfOrderDropped[c],
        summary.sync.lateMissing[c]);
  }
  for (const auto& output : summary.outputs) spdlog::info("wrote {}", output);
}

}  // namespace

int main(int argc, char** argv) {
  bool help = false;
  const auto arguments = parseArguments(argc, argv, help);
  if (!arguments) return help ? 0 : 2;

  daemon::Config config;
  try {
    config = daemon::loadConfig(arguments->configFile);
  } catch (const daemon::ConfigError& e) {
    for (const auto& message : e.messages()) fmt::print(stderr, "surroundd: {}\n", message);
    fmt::print(stderr, "surroundd: {} error(s) in the config; nothing was started\n",
               e.messages().size());
    return 2;
  }
  if (arguments->checkOnly) {
    fmt::print("surroundd: {}: good ({} cameras, {} outputs)\n", arguments->configFile,
               config.cameras.size(), config.outputs.size());
    return 0;
  }
  if (arguments->pacing) config.capture.pacing = *arguments->pacing;
  daemon::setUpLogging(arguments->logLevel.value_or(config.logLevel));
  installSignalHandlers();

  try {
    daemon::Pipeline pipeline(config);
    auto service = daemon::ServiceNotifier::fromEnvironment();
    const auto summary = pipeline.run(stopRequested, &service);
    logSummary(summary);
    return summary.failedOutputs == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
}
