#pragma once
// surroundd's own output types, one source file each (daemon/outputs/<type>_output.cpp), listed in
// builtInOutputTypes() (output_types.cpp).

#include <optional>
#include <vector>

#include "daemon/config/output_type.hpp"
#include "render/outputs/video_encoder.hpp"

namespace surroundd::daemon {

// In the order the config's messages list them; a type this build leaves out is there with how to
// build it in.
std::vector<OutputType> builtInOutputTypes();
// Registers them (daemon/config/output_type.hpp), once however often it is called: what every
// program that reads a config does first.
void registerBuiltInOutputTypes();

OutputType videoOutputType();      // H.264 files, segmented or not (video_output.cpp)
OutputType networkOutputType();    // H.264 in MPEG-TS over UDP (video_output.cpp)
OutputType httpOutputType();       // MJPEG over HTTP and a live page (http_output.cpp)
OutputType rtspOutputType();       // H.264 served over RTSP (rtsp_output.cpp)
OutputType windowOutputType();     // an X11 window (window_output.cpp)
OutputType displayOutputType();    // a DRM/KMS screen (display_output.cpp)
OutputType snapshotOutputType();   // a PNG snapshot (snapshot_output.cpp)
OutputType recordingOutputType();  // the cameras' own streams and a rig file (recording_output.cpp)

// The H.264 encoder's keys, one rule for every type that encodes (video_output.cpp): which
// encoder, its quality, x264's preset, the pixel format; checkEncoder() tells one this FFmpeg
// lacks.
ConfigKey<OutputConfig> encoderKey();
ConfigKey<OutputConfig> crfKey();
ConfigKey<OutputConfig> presetKey();
ConfigKey<OutputConfig> pixelFormatKey();
void checkEncoder(YamlObject& item, OutputConfig& output);
// The encoder's settings from those keys and the stream's size and rate (no path or URL).
render::VideoEncoderSettings encoderSettings(const OutputConfig& output,
                                             const OutputContext& context);

// `present: picture | egl` of the types that can show the surround view as OpenGL drew it (window,
// display; view_present.cpp): the key, with its one-line doc (a literal), and the rule that egl
// shows the surround stream only.
ConfigKey<OutputConfig> presentKey(std::string_view doc);
void checkPresent(YamlObject& item, const OutputConfig& output, std::string_view type);
// The renderer such an output draws through, which must be on `platform` (where the output shows
// it); else RenderError naming the output (`shown`: "window on :1") and `where` ("X server").
render::EglContext& presentingRenderer(const OutputContext& context, render::EglPlatform platform,
                                       std::string_view shown, std::string_view where);

// `listen: ADDRESS:PORT` of the types that serve (http, rtsp), `defaultPort` when absent; and the
// rule that two of a type cannot listen on one port (listen_key.cpp).
ConfigKey<OutputConfig> listenKey(int defaultPort);
// Who may watch a server's output (render::Credentials, read when the config is).
ConfigKey<OutputConfig> passwordFileKey();
// A server listening beyond 127.0.0.0/8 must say who may watch (an error on `listen` otherwise).
void requireCredentialsBeyondThisMachine(YamlObject& item, const OutputConfig& o);
std::optional<OutputConflict> sharesPort(const OutputConfig& earlier, const OutputConfig& output);

}  // namespace surroundd::daemon
