#pragma once
// Internal to render/outputs (and its tests): a top-level window of a fixed size on an
// XlibDisplay, mapped and shown before the constructor returns, that the user may close. What it
// shows is its owner's to draw: X11WindowSink's picture, EglWindow's EGL surface.
//
// Error policy: the constructor throws RenderError naming the display (the window not shown
// within 5 s, the display gone while opening). The user closing the window (WM_DELETE_WINDOW, or
// another client destroying it) and the server going away are states, not errors.
//
// Include this header after every other one (Xlib's macros: see xlib_display.hpp). One thread at
// a time, as its display.

#include <functional>
#include <string>
#include <string_view>

#include <opencv2/core.hpp>

#include "render/outputs/xlib_display.hpp"

namespace surroundd::render {

class XlibWindow {
 public:
  enum class State { kOpen, kClosedByUser, kDisplayLost };

  // `display` must outlive the window. `visual`: the window's visual (depth, colormap).
  // `releaseContents` frees what draws into the window (a picture, an EGL surface) when it closes,
  // just before the window itself goes.
  XlibWindow(XlibDisplay& display, const XVisualInfo& visual, const std::string& title,
             cv::Size size, std::function<void()> releaseContents);
  XlibWindow(const XlibWindow&) = delete;
  XlibWindow& operator=(const XlibWindow&) = delete;

  // Handles the events that arrived (close, map, expose) without waiting for more; returns whether
  // the window was uncovered since (Expose) and should be drawn again.
  bool handleEvents();
  // Takes the window off the screen and frees it; the display stays.
  void close(State why);

  State state() const { return state_; }
  bool open() const { return state_ == State::kOpen; }
  ::Window id() const { return window_.get(); }
  XlibDisplay& display() const { return display_; }
  // "" while open, else "; closed by the user" or "; the display went away".
  std::string_view stopReason() const;

 private:
  // Returns whether the event asks for the window to be drawn again.
  bool handle(const XEvent& event);
  void waitUntilMapped();

  XlibDisplay& display_;
  std::function<void()> releaseContents_;
  Atom wmProtocols_;
  Atom wmDeleteWindow_;
  XlibResource colormap_;
  XlibResource window_;
  State state_ = State::kOpen;
  bool mapped_ = false;
};

}  // namespace surroundd::render
