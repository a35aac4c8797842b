#pragma once
// `present: picture | egl`, one rule for the output types that can show the surround view as
// OpenGL drew it (window, display). A type's settings hold it as `present`.

#include <string_view>

#include "daemon/config/config_keys.hpp"
#include "daemon/config/output_type.hpp"
#include "render/egl_context.hpp"

namespace surroundd::daemon {

// How a window or display output shows its pictures: read back and handed to it
// (render::X11WindowSink, render::DrmDisplaySink), or the surround view as OpenGL drew it, through
// EGL on the GPU with no read-back (render::EglWindowSink, render::EglDisplaySink; the renderer's
// context is then on that X server, or on that DRM card's GBM device).
enum class ViewPresent { kPicture, kEgl };

// The key, with its one-line doc (a literal).
template <class Settings>
ConfigKey<Settings> presentKey(std::string_view doc) {
  return ConfigKey<Settings>::choice(
      "present", &Settings::present,
      {{"picture", ViewPresent::kPicture}, {"egl", ViewPresent::kEgl}}, doc);
}

// egl shows the surround stream only.
void checkPresent(YamlObject& item, const OutputConfig& output, ViewPresent present,
                  std::string_view type);

// The renderer such an output draws through, which must be on `platform` (where the output shows
// it); else RenderError naming the output (`shown`: "window on :1") and `where` ("X server").
render::EglContext& presentingRenderer(const OutputContext& context, render::EglPlatform platform,
                                       std::string_view shown, std::string_view where);

}  // namespace surroundd::daemon
