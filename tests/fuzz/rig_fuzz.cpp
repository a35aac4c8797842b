// The rig file reader (loadRig) on any text: a rig whose cameras hold what the daemon relies on
// (rig_invariants.hpp), or ConfigError; anything else is a finding.

#include <cstddef>
#include <cstdint>
#include <string>

#include "daemon/config/rig_yaml.hpp"
#include "tests/fuzz/fuzz_support.hpp"
#include "tests/fuzz/rig_invariants.hpp"

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  surroundd::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const auto file = surroundd::fuzz::scratchFolder() / "rig.yaml";
  try {
    const auto rig =
        surroundd::daemon::loadRigText(std::string(surroundd::fuzz::asText(data, size)), file);
    surroundd::fuzz::checkAcceptedCameras(rig.cameras);
  } catch (const surroundd::daemon::ConfigError&) {
    // the documented answer to a bad rig
  }
  return 0;
}
