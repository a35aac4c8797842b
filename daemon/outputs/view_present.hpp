#pragma once
// `present: picture | egl`, one rule for the output types that can show the surround view as
// OpenGL drew it (window, display). A type's settings hold it as `present`.

#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>

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

// egl shows the surround stream only: the check of a type (`type`: "window") whose settings hold
// `present`, for readsSettings().
void checkPresent(YamlObject& item, const OutputConfig& output, ViewPresent present,
                  std::string_view type);
template <class Settings>
auto presentCheck(std::string_view type) {
  return [type](YamlObject& item, const OutputConfig& output, const Settings& settings) {
    checkPresent(item, output, settings.present, type);
  };
}

// The renderer draws in one place (an X server, a card): every egl output of a type (`type`) is
// there. `place` names an output's, as the message says it ("'$DISPLAY'"), and `key` is the key
// that says it. The conflict rule of such a type.
template <class Settings>
auto onePlaceForEgl(std::string_view type, std::string_view where, std::string_view key,
                    std::string (*place)(const Settings&)) {
  return [=](const OutputConfig& earlierOutput,
             const OutputConfig& output) -> std::optional<OutputConflict> {
    const auto& earlier = settingsOf<Settings>(earlierOutput);
    const auto& own = settingsOf<Settings>(output);
    if (earlier.present != ViewPresent::kEgl || own.present != ViewPresent::kEgl ||
        place(earlier) == place(own)) {
      return std::nullopt;
    }
    return OutputConflict{
        std::string(key),
        fmt::format(
            "an egl {} must be on the {} of the renderer, which an earlier egl {} puts on {}", type,
            where, type, place(earlier))};
  };
}

// The renderer such an output draws through, which must be on `platform` (where the output shows
// it); else RenderError naming the output (`shown`: "window on :1") and `where` ("X server").
render::EglContext& presentingRenderer(const OutputContext& context, render::EglPlatform platform,
                                       std::string_view shown, std::string_view where);

}  // namespace surroundd::daemon
