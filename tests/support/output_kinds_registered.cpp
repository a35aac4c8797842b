// Compiled into every test program that may read a config: surroundd's output kinds registered
// before main, as each of surroundd's own programs registers them first (the config library
// starts with none: daemon/config/output_type.hpp).
#include "daemon/outputs/built_in_outputs.hpp"

namespace {

const bool kRegistered = [] {
  surroundd::daemon::registerBuiltInOutputTypes();
  return true;
}();

}  // namespace
