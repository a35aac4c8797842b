#pragma once
// What this build of surroundd is, for every program's --version: the version, and the optional
// parts it was built with and without (cmake/OptionalParts.cmake), so that an integrator can tell
// from the installed programs whether, say, the RTSP output is in.

#include <string>
#include <string_view>

namespace surroundd {

// "<program> <version>", then a line of the parts built in and one of those left out.
std::string versionText(std::string_view program);

// How to build in the optional part `part` (OptionalParts.cmake's name: "HTTP", "LIBCAMERA"):
// "configure with -DSURROUNDD_WITH_HTTP=ON (needs libmicrohttpd-dev libturbojpeg0-dev)", for the
// message that refuses what a build leaves out. Throws std::logic_error for a part there is not.
std::string howToBuildIn(std::string_view part);

}  // namespace surroundd
