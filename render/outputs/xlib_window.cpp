#include <chrono>
#include <utility>

#include <fmt/format.h>
#include <poll.h>

#include "render/render_error.hpp"

// After every other header: Xlib's macros.
#include "render/outputs/xlib_window.hpp"

namespace surroundd::render {
namespace {

using Clock = std::chrono::steady_clock;

// How long the server (and a window manager, which may decorate and place the window first) may
// take to show a new window.
constexpr auto kMapTimeout = std::chrono::seconds(5);

::Window createWindow(XlibDisplay& display, const XVisualInfo& visual, Colormap colormap,
                      cv::Size size) {
  XSetWindowAttributes attributes{};
  attributes.colormap = colormap;
  attributes.background_pixel = 0;  // black until the first frame
  attributes.border_pixel = 0;
  attributes.event_mask = ExposureMask | StructureNotifyMask;
  return XCreateWindow(display.get(), RootWindow(display.get(), visual.screen), 0, 0,
                       static_cast<unsigned>(size.width), static_cast<unsigned>(size.height), 0,
                       visual.depth, InputOutput, visual.visual,
                       CWColormap | CWBackPixel | CWBorderPixel | CWEventMask, &attributes);
}

}  // namespace

XlibWindow::XlibWindow(XlibDisplay& display, const XVisualInfo& visual, const std::string& title,
                       cv::Size size, std::function<void()> releaseContents)
    : display_(display),
      releaseContents_(std::move(releaseContents)),
      wmProtocols_(XInternAtom(display_.get(), "WM_PROTOCOLS", False)),
      wmDeleteWindow_(XInternAtom(display_.get(), "WM_DELETE_WINDOW", False)),
      colormap_(display_,
                XCreateColormap(display_.get(), RootWindow(display_.get(), visual.screen),
                                visual.visual, AllocNone),
                &XFreeColormap),
      window_(display_, createWindow(display_, visual, colormap_.get(), size), &XDestroyWindow) {
  Display* x = display_.get();
  XStoreName(x, window_.get(), title.c_str());  // ICCCM: Latin-1, for old window managers
  XChangeProperty(x, window_.get(), XInternAtom(x, "_NET_WM_NAME", False),
                  XInternAtom(x, "UTF8_STRING", False), 8, PropModeReplace,
                  reinterpret_cast<const unsigned char*>(title.data()),
                  static_cast<int>(title.size()));
  // Pictures are shown 1:1, so the window manager should not resize the window.
  XSizeHints hints{};
  hints.flags = PMinSize | PMaxSize;
  hints.min_width = hints.max_width = size.width;
  hints.min_height = hints.max_height = size.height;
  XSetWMNormalHints(x, window_.get(), &hints);
  Atom protocols = wmDeleteWindow_;
  XSetWMProtocols(x, window_.get(), &protocols, 1);
  display_.sync("creating the window");
  XMapWindow(x, window_.get());
  waitUntilMapped();
  if (display_.lost()) {
    throw RenderError(
        fmt::format("X11 window on {}: the display went away while opening", display_.name()));
  }
}

void XlibWindow::waitUntilMapped() {
  const auto deadline = Clock::now() + kMapTimeout;
  for (;;) {
    handleEvents();
    if (mapped_ || state_ != State::kOpen) return;
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) {
      throw RenderError(fmt::format("X11 window on {}: the window was not shown within {} s",
                                    display_.name(), kMapTimeout.count()));
    }
    pollfd connection{ConnectionNumber(display_.get()), POLLIN, 0};
    ::poll(&connection, 1, static_cast<int>(left.count()));
  }
}

bool XlibWindow::handleEvents() {
  bool exposed = false;
  while (state_ == State::kOpen && XPending(display_.get()) > 0) {
    XEvent event{};
    XNextEvent(display_.get(), &event);
    exposed = handle(event) || exposed;
  }
  if (state_ == State::kOpen && display_.lost()) close(State::kDisplayLost);
  return exposed && open();
}

bool XlibWindow::handle(const XEvent& event) {
  switch (event.type) {
    case Expose:
      return event.xexpose.count == 0;  // once per series of exposed rectangles
    case MapNotify:
      mapped_ = true;
      break;
    case UnmapNotify:
      mapped_ = false;
      break;
    case DestroyNotify:  // another client destroyed it
      window_.release();
      close(State::kClosedByUser);
      break;
    case ClientMessage:
      if (event.xclient.message_type == wmProtocols_ && event.xclient.format == 32 &&
          static_cast<Atom>(event.xclient.data.l[0]) == wmDeleteWindow_) {
        close(State::kClosedByUser);
      }
      break;
    default:
      break;
  }
  return false;
}

void XlibWindow::close(State why) {
  state_ = why;
  releaseContents_();
  window_.reset();
  // Off the screen when this returns; errors about a window that is going away do not matter.
  display_.syncForErrorCode();
}

std::string_view XlibWindow::stopReason() const {
  switch (state_) {
    case State::kOpen:
      return "";
    case State::kClosedByUser:
      return "; closed by the user";
    case State::kDisplayLost:
      return "; the display went away";
  }
  return "";
}

}  // namespace surroundd::render
