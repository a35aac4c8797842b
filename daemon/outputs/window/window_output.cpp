#include "daemon/outputs/window/window_output.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

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
  const auto& own = settingsOf<WindowOutputSettings>(output);
  render::X11WindowSettings settings{own.display, own.title, context.pictureSize};
  if (own.present == ViewPresent::kPicture) {
    return queuedSink(std::make_unique<render::X11WindowSink>(std::move(settings)), context,
                      kWindowQueue);
  }
  const std::string shown =
      fmt::format("window on {}", own.display.empty() ? "$DISPLAY" : own.display);
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
  const auto& own = settingsOf<WindowOutputSettings>(output);
  if (own.present != ViewPresent::kEgl) return nullptr;
  auto display = std::make_shared<render::XlibDisplay>(own.display);
  void* native = display->get();
  return std::make_unique<render::EglContext>(render::EglPlatform::kX11, native,
                                              std::move(display));
}

// How the conflict names a window's X server.
std::string serverName(const WindowOutputSettings& settings) {
  return fmt::format("'{}'", settings.display.empty() ? "$DISPLAY" : settings.display);
}

}  // namespace

OutputType windowOutputType() {
  OutputType type;
  type.name = "window";
  using Key = ConfigKey<WindowOutputSettings>;
  readsSettings<WindowOutputSettings>(
      type,
      {
          // Empty, its default, is $DISPLAY: the reference shows an example.
          Key::text("display", &WindowOutputSettings::display, "X display", Shown::kExample),
          Key::text("title", &WindowOutputSettings::title, "the window's title"),
          presentKey<WindowOutputSettings>(
              "how it shows the view: picture (read back, sent to the server) or egl (drawn into "
              "the window on the GPU; the renderer then runs on that X server)"),
      },
      presentCheck<WindowOutputSettings>("window"));
  type.conflict = onePlaceForEgl<WindowOutputSettings>("window", "X server", "display", serverName);
  type.openPictureSink = openWindow;
  type.openRenderer = openRendererOnServer;
  return type;
}

}  // namespace surroundd::daemon
