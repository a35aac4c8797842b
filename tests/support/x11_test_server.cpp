#include "tests/support/x11_test_server.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <unistd.h>

#include "render/outputs/xlib_display.hpp"  // after every other header: Xlib's macros
#include "render/render_error.hpp"

namespace surroundd::testing {
namespace {

using Clock = std::chrono::steady_clock;

constexpr auto kStartTimeout = std::chrono::seconds(10);

// Reads what Xvfb writes to its -displayfd descriptor: the display number and a newline.
std::string readDisplayNumber(int descriptor, Clock::time_point deadline) {
  std::string text;
  while (text.find('\n') == std::string::npos) {
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now());
    pollfd readable{descriptor, POLLIN, 0};
    if (left.count() <= 0 || ::poll(&readable, 1, static_cast<int>(left.count())) <= 0) break;
    std::array<char, 16> buffer{};
    const auto count = ::read(descriptor, buffer.data(), buffer.size());
    if (count <= 0) break;  // Xvfb exited
    text.append(buffer.data(), static_cast<std::size_t>(count));
  }
  const auto end = text.find('\n');
  return end == std::string::npos ? std::string() : text.substr(0, end);
}

}  // namespace

XvfbServer::XvfbServer(std::vector<std::string> extraArguments) {
  if (!std::filesystem::exists(kPath)) {
    throw std::runtime_error(
        fmt::format("{} not found: scripts/install-deps.sh installs it (package xvfb)", kPath));
  }
  const auto deadline = Clock::now() + kStartTimeout;
  std::array<int, 2> pipe{};
  if (::pipe2(pipe.data(), O_CLOEXEC) != 0) throw std::runtime_error("pipe2 failed");
  ::fcntl(pipe[1], F_SETFD, 0);  // the write end goes to Xvfb
  // -noreset: by default an X server resets when its last client disconnects (as the probe below
  // does), and connections made during the reset fail.
  std::vector<std::string> arguments{kPath,       "-displayfd", std::to_string(pipe[1]),
                                     "-screen",   "0",          "1280x800x24",
                                     "-nolisten", "tcp",        "-noreset"};
  arguments.insert(arguments.end(), extraArguments.begin(), extraArguments.end());
  process_ = std::make_unique<ChildProcess>(std::move(arguments), dir_ / "xvfb.log");
  ::close(pipe[1]);
  const std::string number = readDisplayNumber(pipe[0], deadline);
  ::close(pipe[0]);
  if (number.empty()) {
    throw std::runtime_error("Xvfb did not start within 10 s; it said:\n" + process_->output());
  }
  display_ = ":" + number;
  // Xvfb writes the number once it listens; a connection is what the tests need.
  for (;;) {
    try {
      const render::XlibDisplay probe(display_);
      return;
    } catch (const render::RenderError&) {
      if (Clock::now() > deadline) throw;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

XvfbServer::~XvfbServer() { stop(); }

void XvfbServer::stop() {
  if (!process_) return;
  process_->signal(SIGTERM);
  process_->wait();
  process_.reset();
}

X11Observer::X11Observer(const std::string& display)
    : display_(std::make_unique<render::XlibDisplay>(display)) {}

X11Observer::~X11Observer() = default;

cv::Mat X11Observer::contents(unsigned long window) const {
  Display* x = display_->get();
  XWindowAttributes attributes{};
  XGetWindowAttributes(x, window, &attributes);
  display_->sync("reading the window's attributes");
  XImage* image = XGetImage(x, window, 0, 0, static_cast<unsigned>(attributes.width),
                            static_cast<unsigned>(attributes.height), AllPlanes, ZPixmap);
  display_->sync("reading the window");
  if (image == nullptr) throw std::runtime_error("XGetImage gave nothing");
  const Visual& visual = *attributes.visual;
  const auto channel = [](unsigned long pixel, unsigned long mask) {
    return static_cast<std::uint8_t>((pixel & mask) >> std::countr_zero(mask));
  };
  cv::Mat bgr(attributes.height, attributes.width, CV_8UC3);
  for (int row = 0; row < bgr.rows; ++row) {
    auto* out = bgr.ptr<cv::Vec3b>(row);
    for (int column = 0; column < bgr.cols; ++column) {
      const unsigned long pixel = XGetPixel(image, column, row);
      out[column] = cv::Vec3b(channel(pixel, visual.blue_mask), channel(pixel, visual.green_mask),
                              channel(pixel, visual.red_mask));
    }
  }
  XDestroyImage(image);
  return bgr;
}

std::vector<unsigned long> X11Observer::topLevelWindows() const {
  Display* x = display_->get();
  ::Window root = 0;
  ::Window parent = 0;
  ::Window* children = nullptr;
  unsigned count = 0;
  XQueryTree(x, DefaultRootWindow(x), &root, &parent, &children, &count);
  display_->sync("listing the windows");
  const std::span<::Window> list(children, count);
  std::vector<unsigned long> windows(list.begin(), list.end());
  if (children != nullptr) XFree(children);
  return windows;
}

bool X11Observer::exists(unsigned long window) const {
  const std::vector<unsigned long> windows = topLevelWindows();
  return std::ranges::find(windows, window) != windows.end();
}

unsigned long X11Observer::windowTitled(const std::string& wanted) const {
  for (const unsigned long window : topLevelWindows()) {
    if (title(window) == wanted) return window;
  }
  return 0;
}

std::string X11Observer::title(unsigned long window) const {
  Display* x = display_->get();
  Atom type = 0;
  int format = 0;
  unsigned long items = 0;
  unsigned long after = 0;
  unsigned char* data = nullptr;
  XGetWindowProperty(x, window, XInternAtom(x, "_NET_WM_NAME", False), 0, 1024, False,
                     XInternAtom(x, "UTF8_STRING", False), &type, &format, &items, &after, &data);
  display_->sync("reading the window's title");
  if (data == nullptr) return {};
  std::string text(reinterpret_cast<const char*>(data), items);
  XFree(data);
  return text;
}

void X11Observer::sendDeleteWindow(unsigned long window) const {
  Display* x = display_->get();
  XEvent event{};
  event.xclient.type = ClientMessage;
  event.xclient.window = window;
  event.xclient.message_type = XInternAtom(x, "WM_PROTOCOLS", False);
  event.xclient.format = 32;
  event.xclient.data.l[0] = static_cast<long>(XInternAtom(x, "WM_DELETE_WINDOW", False));
  event.xclient.data.l[1] = CurrentTime;
  // No event mask: the event goes to the client that created the window.
  XSendEvent(x, window, False, NoEventMask, &event);
  display_->sync("sending WM_DELETE_WINDOW");
}

void X11Observer::cover(unsigned long window) {
  Display* x = display_->get();
  XWindowAttributes attributes{};
  XGetWindowAttributes(x, window, &attributes);
  XSetWindowAttributes settings{};
  settings.override_redirect = True;
  settings.background_pixel = WhitePixel(x, DefaultScreen(x));
  cover_ = XCreateWindow(x, DefaultRootWindow(x), attributes.x, attributes.y,
                         static_cast<unsigned>(attributes.width),
                         static_cast<unsigned>(attributes.height), 0, CopyFromParent, InputOutput,
                         nullptr, CWOverrideRedirect | CWBackPixel, &settings);
  XMapRaised(x, cover_);
  display_->sync("covering the window");
}

void X11Observer::uncover() {
  XDestroyWindow(display_->get(), cover_);
  cover_ = 0;
  display_->sync("uncovering the window");
}

}  // namespace surroundd::testing
