// Compiled into every test program that may read a config: surroundd's output kinds registered
// before main, as each of surroundd's own programs registers them first (the config library
// starts with none: daemon/config/output_type.hpp).
#include "daemon/outputs/built_in_outputs.hpp"

namespace {

// A registration that throws is the program's own error: the test program ends at once.
const bool kRegistered = [] {  // NOLINT(cert-err58-cpp)
  surroundd::daemon::registerBuiltInOutputTypes();
  return true;
}();

}  // namespace
