#pragma once
// The `window` output type: an X11 window on a desk. With `present: picture`
// (render::X11WindowSink) it is handed each picture read back, and shows it from a thread of its
// own behind a queue; with `present: egl` (render::EglWindowSink) it shows the surround view as
// OpenGL drew it, on the renderer's thread, through EGL: the renderer's context is then made on
// the window's X server.

#include <string>

#include "daemon/config/output_type.hpp"
#include "daemon/outputs/view_present.hpp"

namespace surroundd::daemon {

struct WindowOutputSettings {
  std::string display;  // empty: $DISPLAY
  std::string title = "surroundd";
  ViewPresent present = ViewPresent::kPicture;

  bool operator==(const WindowOutputSettings&) const = default;
};

OutputType windowOutputType();

}  // namespace surroundd::daemon
