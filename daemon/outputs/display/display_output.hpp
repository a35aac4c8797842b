#pragma once
// The `display` output type: a screen driven through DRM/KMS. With `present: picture`
// (render::DrmDisplaySink) it is handed each picture read back, and its page flips wait for
// vblank on a thread of their own behind a queue; with `present: egl` (render::EglDisplaySink) it
// shows the surround view as OpenGL drew it, on the renderer's thread, through EGL: the renderer's
// context is then made on the card's GBM device, and the card is opened (as its master) for it.

#include <filesystem>
#include <string>

#include "daemon/config/output_type.hpp"
#include "daemon/outputs/view_present.hpp"

namespace surroundd::daemon {

struct DisplayOutputSettings {
  std::filesystem::path device;  // empty: the first card with a connected connector
  std::string connector;         // e.g. HDMI-A-1; empty: the first connected one
  ViewPresent present = ViewPresent::kPicture;

  bool operator==(const DisplayOutputSettings&) const = default;
};

OutputType displayOutputType();

}  // namespace surroundd::daemon
