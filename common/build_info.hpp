#pragma once
// What this build of surroundd is, for every program's --version: the version, and the optional
// parts it was built with and without (cmake/OptionalParts.cmake), so that an integrator can tell
// from the installed programs whether, say, the RTSP output is in.

#include <string>
#include <string_view>

namespace surroundd {

// "<program> <version>", then a line of the parts built in and one of those left out.
std::string versionText(std::string_view program);

}  // namespace surroundd
