#pragma once
// Internal to render/ (and its tests): an Xlib connection whose errors become exceptions or a
// "lost" state instead of Xlib's defaults, which call exit(1) on any protocol error and when the
// server goes away — unacceptable in a daemon whose X window is one optional output.
//
// How: the first XlibDisplay installs process-wide Xlib error handlers that record errors of the
// connections opened here on their XlibDisplay and pass every other connection's errors on to the
// handlers installed before; an I/O error (server gone) marks the connection lost, and every later
// request on it is a no-op. Requests are checked with sync(), which waits for the server (XSync)
// and throws the first error they caused.
// Needs libX11 1.7 or later (XSetIOErrorExitHandler; Debian 12 has 1.8).
//
// Include this header after every other one: Xlib defines macros (None, Bool, Status, Complex, ...)
// that break OpenCV's and GoogleTest's headers.
//
// Threading: one XlibDisplay is used by one thread at a time.

#include <string>
#include <string_view>

#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <X11/extensions/XShm.h>

namespace surroundd::render {

class XlibDisplay {
 public:
  // Opens `name` (empty: $DISPLAY); throws RenderError naming it ("cannot open display ':42'").
  explicit XlibDisplay(const std::string& name);
  ~XlibDisplay();
  XlibDisplay(const XlibDisplay&) = delete;
  XlibDisplay& operator=(const XlibDisplay&) = delete;

  Display* get() const { return display_; }
  // The display's name as Xlib resolved it (":42", or $DISPLAY's value).
  const std::string& name() const { return name_; }
  // Whether the connection broke (the server went away or the socket failed).
  bool lost() const { return lost_; }

  // Waits until the server has handled every request so far; throws RenderError naming `what` and
  // the first X error they caused. Returns at once when the connection is lost.
  void sync(std::string_view what);
  // As sync(), but returns the error code of the first error (0: none) instead of throwing.
  int syncForErrorCode();

 private:
  friend struct XlibErrorHandlers;

  Display* display_ = nullptr;
  std::string name_;
  bool lost_ = false;
  // The first error since the last sync (error_code 0: none), recorded by the error handler.
  XErrorEvent firstError_{};
};

// One server-side resource (window, colormap) of a connection, freed by `free` on destruction
// unless the connection is gone.
class XlibResource {
 public:
  using Free = int (*)(Display*, XID);

  XlibResource(XlibDisplay& display, XID id, Free free)
      : display_(&display), id_(id), free_(free) {}
  ~XlibResource() { reset(); }
  XlibResource(const XlibResource&) = delete;
  XlibResource& operator=(const XlibResource&) = delete;

  XID get() const { return id_; }
  // Forgets the resource without freeing it (it is gone already).
  void release() { id_ = 0; }
  void reset() {
    if (id_ != 0 && !display_->lost()) free_(display_->get(), id_);
    id_ = 0;
  }

 private:
  XlibDisplay* display_;
  XID id_;
  Free free_;
};

}  // namespace surroundd::render
