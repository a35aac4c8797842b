// Built instead of guide_command.cpp where SURROUNDD_WITH_HTTP is off: the guide's page needs the
// HTTP server.
#include <stdexcept>

#include "tools/calibrate/guide_command.hpp"

namespace surroundd::calibrate {

void runGuide(const GuideOptions& /*options*/, std::ostream& /*log*/) {
  throw std::runtime_error(
      "surround-calibrate guide: this build has no HTTP server for its page (configure with "
      "-DSURROUNDD_WITH_HTTP=ON; needs libmicrohttpd-dev and libturbojpeg0-dev)");
}

}  // namespace surroundd::calibrate
