#pragma once
// surroundd's own output types, one source file each (daemon/<type>_output.cpp), listed in
// builtInOutputTypes() (output_types.cpp), which the registry (output_type.hpp) starts with.

#include <vector>

#include "daemon/output_type.hpp"

namespace surroundd::daemon {

// In the order the config's messages list them; a type this build leaves out is there with how to
// build it in.
std::vector<OutputType> builtInOutputTypes();

OutputType videoOutputType();      // H.264 files, segmented or not (video_output.cpp)
OutputType networkOutputType();    // H.264 in MPEG-TS over UDP (video_output.cpp)
OutputType httpOutputType();       // MJPEG over HTTP and a live page (http_output.cpp)
OutputType windowOutputType();     // an X11 window (window_output.cpp)
OutputType displayOutputType();    // a DRM/KMS screen (display_output.cpp)
OutputType snapshotOutputType();   // a PNG snapshot (snapshot_output.cpp)
OutputType recordingOutputType();  // the cameras' own streams and a rig file (recording_output.cpp)

// The encoder's quality, one rule for every type that encodes (video_output.cpp).
ConfigKey<OutputConfig> crfKey();

}  // namespace surroundd::daemon
