#include "render/outputs/xlib_display.hpp"

#include <array>
#include <map>
#include <mutex>

#include <fmt/format.h>

#include "render/render_error.hpp"

namespace surroundd::render {

// Xlib's error handlers are process-wide; these route each error to the XlibDisplay whose
// connection it came on, or to the handler that was installed before (Xlib's default or another
// library's) for any other connection.
struct XlibErrorHandlers {
  std::mutex mutex;
  std::map<Display*, XlibDisplay*> displays;
  XErrorHandler previousError = nullptr;
  XIOErrorHandler previousIoError = nullptr;

  // Installed once, on first use, and never removed: a library loaded later may have chained to us.
  static XlibErrorHandlers& instance() {
    static XlibErrorHandlers handlers;
    return handlers;
  }

  XlibErrorHandlers() {
    previousError = XSetErrorHandler(&onError);
    previousIoError = XSetIOErrorHandler(&onIoError);
  }

  XlibDisplay* owner(Display* display) {
    const std::lock_guard lock(mutex);
    const auto found = displays.find(display);
    return found == displays.end() ? nullptr : found->second;
  }

  // Runs on the thread that made the failing request, which is the XlibDisplay's own thread.
  static int onError(Display* display, XErrorEvent* event) {
    auto& self = instance();
    if (auto* owner = self.owner(display)) {
      if (owner->firstError_.error_code == 0) owner->firstError_ = *event;
      return 0;
    }
    return self.previousError(display, event);
  }

  // The server went away. Returning (rather than exiting, as Xlib's default does) leaves the
  // connection marked broken: every later call on it returns at once.
  static int onIoError(Display* display) {
    auto& self = instance();
    if (auto* owner = self.owner(display)) {
      owner->lost_ = true;
      return 0;
    }
    return self.previousIoError(display);
  }

  // After the I/O error handler returns, Xlib (1.7 and later) calls this per-connection handler
  // instead of exit(1).
  static void onIoErrorExit(Display* /*display*/, void* owner) {
    static_cast<XlibDisplay*>(owner)->lost_ = true;
  }
};

XlibDisplay::XlibDisplay(const std::string& name) {
  auto& handlers = XlibErrorHandlers::instance();
  const char* requested = name.empty() ? nullptr : name.c_str();
  name_ = XDisplayName(requested);
  display_ = XOpenDisplay(requested);
  if (display_ == nullptr) {
    throw RenderError(fmt::format("X11 window: cannot open display '{}'{}", name_,
                                  name_.empty() ? " ($DISPLAY is not set)" : ""));
  }
  {
    const std::lock_guard lock(handlers.mutex);
    handlers.displays[display_] = this;
  }
  XSetIOErrorExitHandler(display_, &XlibErrorHandlers::onIoErrorExit, this);
}

XlibDisplay::~XlibDisplay() {
  // Closing a lost connection only frees its memory.
  XCloseDisplay(display_);
  auto& handlers = XlibErrorHandlers::instance();
  const std::lock_guard lock(handlers.mutex);
  handlers.displays.erase(display_);
}

int XlibDisplay::syncForErrorCode() {
  if (!lost_) XSync(display_, False);
  const int code = firstError_.error_code;
  firstError_ = {};
  return code;
}

void XlibDisplay::sync(std::string_view what) {
  if (lost_) return;
  XSync(display_, False);
  const XErrorEvent error = firstError_;
  firstError_ = {};
  if (error.error_code == 0) return;
  std::array<char, 256> text{};
  XGetErrorText(display_, error.error_code, text.data(), static_cast<int>(text.size()));
  throw RenderError(fmt::format("X11 window on {}: {} failed: {} (X request {}.{})", name_, what,
                                text.data(), error.request_code, error.minor_code));
}

}  // namespace surroundd::render
