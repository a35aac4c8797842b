// surroundd: captures or replays the rig's cameras and writes the configured outputs, until
// SIGTERM/SIGINT (every output finalized) or the end of a replay; SIGHUP reloads the config.
//
// Exit codes: 0 done, 1 failed at run time or start-up (a camera or output could not be opened),
// 2 bad command line or config (nothing was opened).

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <optional>
#include <string_view>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "common/build_info.hpp"
#include "daemon/config/config.hpp"
#include "daemon/config/logging.hpp"
#include "daemon/config/rig_yaml.hpp"
#include "daemon/live_cameras.hpp"
#include "daemon/outputs/built_in_outputs.hpp"
#include "daemon/process_start.hpp"
#include "daemon/service.hpp"

namespace {

using namespace surroundd;

constexpr std::string_view kUsage =
    R"(usage: surroundd --config FILE [--log-level LEVEL] [--pacing MODE] [--check-config]
       surroundd --list-cameras

  --config FILE       the YAML config (see config/surroundd.reference.yaml); also -c FILE,
                      --config=FILE (and so for every option with a value)
  --check-config      check the config and that each V4L2 camera's device is there and offers
                      the format and size asked (opened only to ask): say what is wrong (exit 2)
                      or that it is good (exit 0); nothing streams, no output is opened
  --list-cameras      the V4L2 capture devices (persistent names, formats, sizes and rates) and
                      libcamera's cameras, for a config's camera sources
  --log-level LEVEL   trace, debug, info, warning, error or off; overrides logging.level
  --pacing MODE       realtime or as_fast_as_possible; overrides capture.pacing
  --version           the version, and the optional parts this build has and has not
  --help              this text
)";

// Set from the signal handlers; lock-free atomics are async-signal-safe.
daemon::ServiceSignals signals;
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void requestStop(int /*signal*/) { signals.stop = true; }
extern "C" void requestReload(int /*signal*/) { signals.reload = true; }

void installSignalHandlers() {
  struct sigaction action {};
  sigemptyset(&action.sa_mask);
  action.sa_handler = requestStop;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  action.sa_handler = requestReload;
  sigaction(SIGHUP, &action, nullptr);
  // A network or control client that goes away must not kill the daemon: writes to it fail with
  // EPIPE instead, and that output is dropped.
  action.sa_handler = SIG_IGN;
  sigaction(SIGPIPE, &action, nullptr);
}

struct Arguments {
  std::string configFile;
  std::optional<spdlog::level::level_enum> logLevel;
  std::optional<capture::Pacing> pacing;
  bool checkOnly = false;
};

// --check-config: the file, then the devices it names. Returns the exit code.
int checkConfig(const daemon::Config& config, const std::string& file) {
  for (const auto& warning : config.warnings) {
    fmt::print(stderr, "surroundd: warning: {}\n", warning);
  }
  std::vector<std::string> problems;
  try {
    std::vector<std::string> said;
    problems = daemon::cameraDeviceProblems(daemon::withAutoDevices(config.cameras, said));
    for (const auto& line : said) fmt::print("surroundd: {}\n", line);
  } catch (const std::runtime_error& e) {
    problems.emplace_back(e.what());
  }
  for (const auto& problem : problems) fmt::print(stderr, "surroundd: {}\n", problem);
  if (!problems.empty()) {
    fmt::print(stderr,
               "surroundd: {}: the file is good ({} cameras, {} outputs), but its cameras "
               "cannot be opened here as it asks ({} problem(s)); nothing was started\n",
               file, config.cameras.size(), config.outputs.size(), problems.size());
    return 2;
  }
  fmt::print("surroundd: {}: good ({} cameras, {} outputs)\n", file, config.cameras.size(),
             config.outputs.size());
  return 0;
}

// nullopt after printing what was wrong (or the help or version text, with `help` set).
std::optional<Arguments> parseArguments(int argc, char** argv, bool& help) {
  Arguments arguments;
  const auto fail = [](std::string_view message) {
    fmt::print(stderr, "surroundd: {}\n{}", message, kUsage);
    return std::nullopt;
  };
  for (int i = 1; i < argc; ++i) {
    std::string_view flag = argv[i];
    if (flag == "--help" || flag == "-h") {
      help = true;
      fmt::print("{}", kUsage);
      return std::nullopt;
    }
    if (flag == "--version") {
      help = true;
      fmt::print("{}", versionText("surroundd"));
      return std::nullopt;
    }
    if (flag == "--check-config") {
      arguments.checkOnly = true;
      continue;
    }
    if (flag == "--list-cameras") {
      help = true;
      daemon::listCameras(std::cout);
      return std::nullopt;
    }
    // --name=value, as GNU programs take it, and -c for --config.
    std::optional<std::string_view> attached;
    if (const auto equals = flag.find('='); flag.starts_with("--") && equals != flag.npos) {
      attached = flag.substr(equals + 1);
      flag = flag.substr(0, equals);
    }
    if (flag == "-c") flag = "--config";
    if (attached && (flag == "--check-config" || flag == "--help" || flag == "--version" ||
                     flag == "--list-cameras")) {
      return fail(fmt::format("'{}' takes no value", flag));
    }
    if (!attached && i + 1 >= argc) return fail(fmt::format("'{}' needs a value", flag));
    const std::string_view value = attached ? *attached : std::string_view(argv[++i]);
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

}  // namespace

int main(int argc, char** argv) {
  const auto processStart = daemon::processStartTime();  // first: its fallback is "now"
  bool help = false;
  const auto arguments = parseArguments(argc, argv, help);
  if (!arguments) return help ? 0 : 2;

  daemon::registerBuiltInOutputTypes();
  daemon::Config config;
  try {
    config = daemon::loadConfig(arguments->configFile);
  } catch (const daemon::ConfigError& e) {
    for (const auto& message : e.messages()) fmt::print(stderr, "surroundd: {}\n", message);
    fmt::print(stderr, "surroundd: {} error(s) in the config; nothing was started\n",
               e.messages().size());
    return 2;
  }
  if (arguments->checkOnly) return checkConfig(config, arguments->configFile);
  if (arguments->pacing) config.capture.pacing = *arguments->pacing;
  daemon::setUpLogging(arguments->logLevel.value_or(config.logLevel));
  for (const auto& warning : config.warnings) spdlog::warn("{}", warning);
  installSignalHandlers();

  try {
    daemon::Service service(std::move(config), signals, daemon::ServiceNotifier::fromEnvironment(),
                            processStart);
    return service.run();
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
}
