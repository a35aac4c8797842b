// The config reader (loadConfig) on any text: it either gives a config or throws ConfigError
// listing the problems. Anything else escaping it (a YAML or standard-library exception), a crash
// or undefined behaviour is a finding. The file sits in an empty folder, so relative paths it
// names (rig files, masks, recordings) do not exist.

#include <cstddef>
#include <cstdint>
#include <string>

#include "daemon/config.hpp"
#include "daemon/yaml_reader.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  surroundd::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const auto file = surroundd::fuzz::scratchFolder() / "surroundd.yaml";
  try {
    (void)surroundd::daemon::loadConfigText(std::string(surroundd::fuzz::asText(data, size)), file);
  } catch (const surroundd::daemon::ConfigError&) {
    // the documented answer to a bad config
  }
  return 0;
}
