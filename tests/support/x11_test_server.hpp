#pragma once
// An X server of the test's own (Xvfb, no window manager), and a second client connection that
// looks at windows the way a user's screen shows them. Xlib stays out of this header: its macros
// break GoogleTest's and OpenCV's headers.

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "tests/support/child_process.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd::render {
class XlibDisplay;
}

namespace surroundd::testing {

class XvfbServer {
 public:
  static constexpr const char* kPath = "/usr/bin/Xvfb";

  // Starts Xvfb (1280×800, 24-bit, no TCP, no reset) on a display number it picks itself
  // (-displayfd), with `extraArguments`, and waits until it accepts connections. Throws
  // std::runtime_error with Xvfb's output if it does not within 10 s.
  explicit XvfbServer(std::vector<std::string> extraArguments = {});
  // Stops the server (SIGTERM, so that it removes its sockets) and waits for it.
  ~XvfbServer();
  XvfbServer(const XvfbServer&) = delete;
  XvfbServer& operator=(const XvfbServer&) = delete;

  // ":N"
  const std::string& display() const { return display_; }
  // Stops the server now, as if it crashed or the session ended.
  void stop();

 private:
  TempDir dir_;
  std::unique_ptr<ChildProcess> process_;
  std::string display_;
};

class X11Observer {
 public:
  explicit X11Observer(const std::string& display);
  ~X11Observer();
  X11Observer(const X11Observer&) = delete;
  X11Observer& operator=(const X11Observer&) = delete;

  // What the window shows on the screen, as 8-bit BGR.
  cv::Mat contents(unsigned long window) const;
  bool exists(unsigned long window) const;
  // The top-level window titled `title` (_NET_WM_NAME); 0 if none is.
  unsigned long windowTitled(const std::string& title) const;
  // The window's title (_NET_WM_NAME).
  std::string title(unsigned long window) const;
  // What a window manager sends when the user clicks the window's close button.
  void sendDeleteWindow(unsigned long window) const;
  // Covers the window with a white one of our own, until uncover().
  void cover(unsigned long window);
  void uncover();

 private:
  std::vector<unsigned long> topLevelWindows() const;

  std::unique_ptr<render::XlibDisplay> display_;
  unsigned long cover_ = 0;
};

}  // namespace surroundd::testing
