// The `window` output: an X11 window on a desk (render::X11WindowSink), shown from a thread of its
// own behind a queue.
#include "daemon/built_in_outputs.hpp"
#include "render/outputs/x11_window_sink.hpp"

namespace surroundd::daemon {
namespace {

// A window shows the newest picture: one may wait while the one before is shown.
constexpr std::size_t kWindowQueue = 1;

std::unique_ptr<render::FrameSink> openWindow(const OutputConfig& output,
                                              const OutputContext& context) {
  return queuedSink(std::make_unique<render::X11WindowSink>(render::X11WindowSettings{
                        output.display, output.title, context.pictureSize}),
                    context, kWindowQueue);
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
  };
  type.openPictureSink = openWindow;
  return type;
}

}  // namespace surroundd::daemon
