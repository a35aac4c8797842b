#include "daemon/outputs/view_present.hpp"

#include <fmt/format.h>

#include "render/render_error.hpp"

namespace surroundd::daemon {

void checkPresent(YamlObject& item, const OutputConfig& output, ViewPresent present,
                  std::string_view type) {
  if (present == ViewPresent::kEgl && output.stream != OutputStream::kSurround) {
    item.error("present", fmt::format("egl shows the surround view as OpenGL draws it: the {}'s "
                                      "stream must be surround",
                                      type));
  }
}

render::EglContext& presentingRenderer(const OutputContext& context, render::EglPlatform platform,
                                       std::string_view shown, std::string_view where) {
  if (context.renderer == nullptr) {
    throw render::RenderError(
        fmt::format("{}: present: egl shows the surround view, and there is no renderer", shown));
  }
  if (context.renderer->platform() != platform) {
    throw render::RenderError(fmt::format(
        "{}: present: egl needs the renderer on this {}, and it runs on the {} platform (the "
        "log's render line says why)",
        shown, where, render::toString(context.renderer->platform())));
  }
  return *context.renderer;
}

}  // namespace surroundd::daemon
