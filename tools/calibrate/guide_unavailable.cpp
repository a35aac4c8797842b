// Built instead of guide_command.cpp and mat_guide_command.cpp where SURROUNDD_WITH_HTTP is off:
// the guide's page needs the HTTP server. Asking this build for it is a usage error (status 2),
// refused before any camera is opened, with how to build it in.
#include "common/build_info.hpp"
#include "tools/calibrate/calibrate_options.hpp"
#include "tools/calibrate/guide/guide_command.hpp"
#include "tools/calibrate/guide/mat_guide_command.hpp"

namespace surroundd::calibrate {
namespace {

[[noreturn]] void refuse() {
  throw UsageError("this build has no HTTP server for its page (" + howToBuildIn("HTTP") + ")");
}

}  // namespace

void runGuide(const GuideOptions& /*options*/, std::ostream& /*log*/) { refuse(); }
void runMatGuide(const MatGuideOptions& /*options*/, std::ostream& /*log*/) { refuse(); }

}  // namespace surroundd::calibrate
