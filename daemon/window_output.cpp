// The `window` output: an X11 window on a desk (render::X11WindowSink), shown from a thread of its
// own behind a queue.
#include "daemon/built_in_outputs.hpp"
#include "render/outputs/x11_window_sink.hpp"

namespace surroundd::daemon {
namespace {

// A window shows the newest picture: one may wait while the one before is shown.
constexpr std::size_t kWindowQueue = 1;

void readWindow(YamlObject& item, OutputConfig& o) {
  o.display = item.string("display", o.display);
  o.title = item.string("title", o.title);
}

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
  type.readSettings = readWindow;
  type.openPictureSink = openWindow;
  return type;
}

}  // namespace surroundd::daemon
