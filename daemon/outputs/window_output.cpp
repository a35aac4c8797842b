// The `window` output: an X11 window on a desk. With `present: picture` (render::X11WindowSink)
// it is handed each picture read back, and shows it from a thread of its own behind a queue; with
// `present: egl` (render::EglWindowSink) it shows the surround view as OpenGL drew it, on the
// renderer's thread, through EGL: the renderer's context is then made on the window's X server.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "daemon/outputs/built_in_outputs.hpp"
#include "render/outputs/egl_window_sink.hpp"
#include "render/outputs/x11_window_sink.hpp"

// After every other header: Xlib's macros.
#include "render/outputs/xlib_display.hpp"

namespace surroundd::daemon {
namespace {

// A window shows the newest picture: one may wait while the one before is shown.
constexpr std::size_t kWindowQueue = 1;

std::unique_ptr<render::FrameSink> openWindow(const OutputConfig& output,
                                              const OutputContext& context) {
  render::X11WindowSettings settings{output.display, output.title, context.pictureSize};
  if (output.present == ViewPresent::kPicture) {
    return queuedSink(std::make_unique<render::X11WindowSink>(std::move(settings)), context,
                      kWindowQueue);
  }
  const std::string shown =
      fmt::format("window on {}", output.display.empty() ? "$DISPLAY" : output.display);
  render::EglContext& gl =
      presentingRenderer(context, render::EglPlatform::kX11, shown, "X server");
  if (gl.software()) {
    spdlog::warn(
        "{}: present: egl on a renderer that runs on the CPU, whose swap copies each picture on "
        "the renderer's thread; present: picture is faster here",
        shown);
  }
  return std::make_unique<render::EglWindowSink>(gl, std::move(settings));
}

// The renderer's context on the X server of a window that shows the views through EGL; it keeps
// its own connection there.
std::unique_ptr<render::EglContext> openRendererOnServer(const OutputConfig& output) {
  if (output.present != ViewPresent::kEgl) return nullptr;
  auto display = std::make_shared<render::XlibDisplay>(output.display);
  void* native = display->get();
  return std::make_unique<render::EglContext>(render::EglPlatform::kX11, native,
                                              std::move(display));
}

void checkWindow(YamlObject& item, OutputConfig& output) { checkPresent(item, output, "window"); }

// The renderer draws on one X server: every egl window is on it.
std::optional<OutputConflict> otherServer(const OutputConfig& earlier, const OutputConfig& output) {
  if (earlier.present != ViewPresent::kEgl || output.present != ViewPresent::kEgl ||
      earlier.display == output.display) {
    return std::nullopt;
  }
  return OutputConflict{
      "display", fmt::format("an egl window must be on the X server of the renderer, which an "
                             "earlier egl window puts on '{}'",
                             earlier.display.empty() ? "$DISPLAY" : earlier.display)};
}

}  // namespace

OutputType windowOutputType() {
  OutputType type;
  type.name = "window";
  using Key = ConfigKey<OutputConfig>;
  type.keys = {
      // Empty, its default, is $DISPLAY: the reference shows an example.
      Key::text("display", &OutputConfig::display, "X display", Shown::kExample),
      Key::text("title", &OutputConfig::title, "the window's title"),
      presentKey("how it shows the view: picture (read back, sent to the server) or egl (drawn "
                 "into the window on the GPU; the renderer then runs on that X server)"),
  };
  type.readSettings = checkWindow;
  type.conflict = otherServer;
  type.openPictureSink = openWindow;
  type.openRenderer = openRendererOnServer;
  return type;
}

}  // namespace surroundd::daemon
