// The config reader (loadConfig) on any text: it either gives a config whose cameras hold what the
// daemon relies on (rig_invariants.hpp) and whose panorama and picture sizes are usable, or throws
// ConfigError listing the problems. Anything else escaping it (a YAML or standard-library
// exception), a crash or undefined behaviour is a finding. The file sits in an empty folder, so
// relative paths it names (rig files, masks, recordings) do not exist.

#include <cstddef>
#include <cstdint>
#include <string>

#include "daemon/config/config.hpp"
#include "daemon/config/yaml_reader.hpp"
#include "daemon/outputs/built_in_outputs.hpp"
#include "tests/fuzz/fuzz_support.hpp"
#include "tests/fuzz/rig_invariants.hpp"

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  surroundd::fuzz::quietLogs();
  surroundd::daemon::registerBuiltInOutputTypes();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const auto file = surroundd::fuzz::scratchFolder() / "surroundd.yaml";
  try {
    const auto config =
        surroundd::daemon::loadConfigText(std::string(surroundd::fuzz::asText(data, size)), file);
    surroundd::fuzz::checkAcceptedCameras(config.cameras);
    FUZZ_CHECK(!config.cameras.empty());
    FUZZ_CHECK(config.panorama.widthPx >= 1 && config.panorama.heightPx >= 1);
    FUZZ_CHECK(config.panorama.elevationTopDeg > config.panorama.elevationBottomDeg);
    FUZZ_CHECK(config.render.widthPx >= 1 && config.render.heightPx >= 1);
  } catch (const surroundd::daemon::ConfigError&) {
    // the documented answer to a bad config
  }
  return 0;
}
