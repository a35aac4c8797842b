#pragma once
// surroundd's own output types, a folder each (daemon/outputs/<type>/: its settings, its keys, its
// factory), listed in builtInOutputTypes() (output_types.cpp). What several share is here beside
// them: the H.264 encoder's keys (h264_settings.hpp), a server's (server_settings.hpp), and how a
// view is presented (view_present.hpp).

#include <vector>

#include "daemon/config/output_type.hpp"

namespace surroundd::daemon {

// In the order the config's messages list them; a type this build leaves out is there with how to
// build it in.
std::vector<OutputType> builtInOutputTypes();
// Registers them (daemon/config/output_type.hpp), once however often it is called: what every
// program that reads a config does first.
void registerBuiltInOutputTypes();

}  // namespace surroundd::daemon
