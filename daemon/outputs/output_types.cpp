// The list of surroundd's own output types. The optional ones are compiled in by CMake options
// (SURROUNDD_WITH_HTTP, _RTSP, _X11, _DRM), which only this file and those types' sources see:
// every other object is the same in every build (and ccache hits).
#include <mutex>
#include <string>

#include "common/build_info.hpp"
#include "daemon/outputs/built_in_outputs.hpp"
#include "daemon/outputs/display/display_output.hpp"
#include "daemon/outputs/http/http_output.hpp"
#include "daemon/outputs/recording/recording_output.hpp"
#include "daemon/outputs/rtsp/rtsp_output.hpp"
#include "daemon/outputs/snapshot/snapshot_output.hpp"
#include "daemon/outputs/video/video_output.hpp"
#include "daemon/outputs/window/window_output.hpp"

namespace surroundd::daemon {
namespace {

// A type this build does not have: a config that names it is refused with `howToBuildIt`.
[[maybe_unused]] OutputType leftOut(std::string name, std::string howToBuildIt) {
  OutputType type;
  type.name = std::move(name);
  type.leftOut = std::move(howToBuildIt);
  return type;
}

}  // namespace

std::vector<OutputType> builtInOutputTypes() {
  std::vector<OutputType> types;
  types.push_back(videoOutputType());
  types.push_back(networkOutputType());
#if SURROUNDD_WITH_HTTP
  types.push_back(httpOutputType());
#else
  types.push_back(leftOut("http", howToBuildIn("HTTP")));
#endif
#if SURROUNDD_WITH_RTSP
  types.push_back(rtspOutputType());
#else
  types.push_back(leftOut("rtsp", howToBuildIn("RTSP")));
#endif
#if SURROUNDD_WITH_X11
  types.push_back(windowOutputType());
#else
  types.push_back(leftOut("window", howToBuildIn("X11")));
#endif
#if SURROUNDD_WITH_DRM
  types.push_back(displayOutputType());
#else
  types.push_back(leftOut("display", howToBuildIn("DRM")));
#endif
  types.push_back(snapshotOutputType());
  types.push_back(recordingOutputType());
  return types;
}

void registerBuiltInOutputTypes() {
  static std::once_flag registered;
  std::call_once(registered, [] {
    for (OutputType& type : builtInOutputTypes()) registerOutputType(std::move(type));
  });
}

}  // namespace surroundd::daemon
