#include "render/outputs/x11_window_sink.hpp"

#include <string_view>
#include <type_traits>
#include <utility>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <poll.h>

#include "render/outputs/xlib_display.hpp"  // after every other header: Xlib's macros
#include "render/outputs/xlib_image.hpp"
#include "render/render_error.hpp"

namespace surroundd::render {
namespace {

using Clock = std::chrono::steady_clock;

// How long the server (and a window manager, which may decorate and place the window first) may
// take to show a new window.
constexpr auto kMapTimeout = std::chrono::seconds(5);

XVisualInfo trueColorVisual(XlibDisplay& display) {
  XVisualInfo visual{};
  if (XMatchVisualInfo(display.get(), DefaultScreen(display.get()), 24, TrueColor, &visual) == 0) {
    throw RenderError(fmt::format("X11 window on {}: the display has no 24-bit TrueColor visual",
                                  display.name()));
  }
  return visual;
}

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

struct GcDeleter {
  Display* display;
  // Also frees the GC's client-side memory, so it runs even on a lost connection.
  void operator()(GC gc) const { XFreeGC(display, gc); }
};

}  // namespace

// The X connection, the window and the picture it shows. Members are released in reverse order:
// picture (MIT-SHM detached first), GC, window, colormap, and the connection last.
class X11WindowSink::XlibWindow {
 public:
  explicit XlibWindow(const X11WindowSettings& settings);

  // Shows `bgr` (8-bit BGR of the window's size); false when the display went away meanwhile.
  bool show(const cv::Mat& bgr);
  // Handles the events that arrived (close, expose) without waiting for more.
  void handleEvents();

  bool open() const { return state_ == State::kOpen; }
  const std::string& displayName() const { return display_.name(); }
  ::Window id() const { return window_.get(); }
  bool sharedMemory() const { return image_ && image_->sharedMemory(); }
  std::string_view stopReason() const;

 private:
  enum class State { kOpen, kClosedByUser, kDisplayLost };

  void handle(const XEvent& event);
  void waitUntilMapped();
  // Takes the window off the screen and frees it; the connection stays until destruction.
  void close(State why);

  XlibDisplay display_;
  XVisualInfo visual_;
  Atom wmProtocols_;
  Atom wmDeleteWindow_;
  XlibResource colormap_;
  XlibResource window_;
  std::unique_ptr<std::remove_pointer_t<GC>, GcDeleter> gc_;
  std::unique_ptr<XlibImage> image_;
  State state_ = State::kOpen;
  bool mapped_ = false;
  bool hasPicture_ = false;
  bool redrawInFlight_ = false;  // an Expose redraw the server may still be reading image_ for
};

X11WindowSink::XlibWindow::XlibWindow(const X11WindowSettings& settings)
    : display_(settings.display),
      visual_(trueColorVisual(display_)),
      wmProtocols_(XInternAtom(display_.get(), "WM_PROTOCOLS", False)),
      wmDeleteWindow_(XInternAtom(display_.get(), "WM_DELETE_WINDOW", False)),
      colormap_(display_,
                XCreateColormap(display_.get(), RootWindow(display_.get(), visual_.screen),
                                visual_.visual, AllocNone),
                &XFreeColormap),
      window_(display_, createWindow(display_, visual_, colormap_.get(), settings.size),
              &XDestroyWindow),
      gc_(XCreateGC(display_.get(), window_.get(), 0, nullptr), GcDeleter{display_.get()}) {
  Display* x = display_.get();
  XStoreName(x, window_.get(), settings.title.c_str());  // ICCCM: Latin-1, for old window managers
  XChangeProperty(x, window_.get(), XInternAtom(x, "_NET_WM_NAME", False),
                  XInternAtom(x, "UTF8_STRING", False), 8, PropModeReplace,
                  reinterpret_cast<const unsigned char*>(settings.title.data()),
                  static_cast<int>(settings.title.size()));
  // Frames are shown 1:1, so the window manager should not resize the window.
  XSizeHints hints{};
  hints.flags = PMinSize | PMaxSize;
  hints.min_width = hints.max_width = settings.size.width;
  hints.min_height = hints.max_height = settings.size.height;
  XSetWMNormalHints(x, window_.get(), &hints);
  Atom protocols = wmDeleteWindow_;
  XSetWMProtocols(x, window_.get(), &protocols, 1);
  display_.sync("creating the window");
  image_ = std::make_unique<XlibImage>(display_, visual_, settings.size);
  XMapWindow(x, window_.get());
  waitUntilMapped();
  if (display_.lost()) {
    throw RenderError(
        fmt::format("X11 window on {}: the display went away while opening", display_.name()));
  }
}

void X11WindowSink::XlibWindow::waitUntilMapped() {
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

void X11WindowSink::XlibWindow::handleEvents() {
  while (state_ == State::kOpen && XPending(display_.get()) > 0) {
    XEvent event{};
    XNextEvent(display_.get(), &event);
    handle(event);
  }
  if (state_ == State::kOpen && display_.lost()) close(State::kDisplayLost);
}

void X11WindowSink::XlibWindow::handle(const XEvent& event) {
  switch (event.type) {
    case Expose:
      // Redraw once per series of exposed rectangles; the next show() waits for it to finish.
      if (event.xexpose.count == 0 && hasPicture_) {
        image_->put(window_.get(), gc_.get());
        XFlush(display_.get());
        redrawInFlight_ = true;
      }
      break;
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
}

bool X11WindowSink::XlibWindow::show(const cv::Mat& bgr) {
  if (redrawInFlight_) {
    display_.sync("redrawing the window");
    redrawInFlight_ = false;
  }
  // The const header has a fixed size and type: cvtColor writes into the image's memory and would
  // throw rather than allocate.
  cv::cvtColor(bgr, image_->pixels(), cv::COLOR_BGR2BGRA);
  image_->put(window_.get(), gc_.get());
  display_.sync("showing a frame");
  hasPicture_ = true;
  if (display_.lost()) close(State::kDisplayLost);
  return open();
}

void X11WindowSink::XlibWindow::close(State why) {
  state_ = why;
  image_.reset();
  gc_.reset();
  window_.reset();
  // Off the screen when this returns; errors about a window that is going away do not matter.
  display_.syncForErrorCode();
  redrawInFlight_ = false;
}

std::string_view X11WindowSink::XlibWindow::stopReason() const {
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

X11WindowSink::X11WindowSink(X11WindowSettings settings) : settings_(std::move(settings)) {
  if (settings_.size.width <= 0 || settings_.size.height <= 0) {
    throw RenderError(fmt::format("X11 window: the size must be positive, got {}x{}",
                                  settings_.size.width, settings_.size.height));
  }
  window_ = std::make_unique<XlibWindow>(settings_);
}

X11WindowSink::~X11WindowSink() = default;

void X11WindowSink::consume(const cv::Mat& bgr, const PictureTime& /*time*/) {
  if (bgr.type() != CV_8UC3) {
    throw RenderError(fmt::format("X11 window on {}: frames must be 8-bit BGR, got {}",
                                  window_->displayName(), cv::typeToString(bgr.type())));
  }
  if (bgr.size() != settings_.size) {
    throw RenderError(fmt::format("X11 window on {}: the frame is {}x{}, the window {}x{}",
                                  window_->displayName(), bgr.cols, bgr.rows, settings_.size.width,
                                  settings_.size.height));
  }
  const std::lock_guard lock(xlib_);
  window_->handleEvents();
  if (window_->open() && window_->show(bgr)) ++framesShown_;
  open_ = window_->open();
}

bool X11WindowSink::wantsFrame(std::chrono::nanoseconds /*streamTime*/) const {
  // Reading the window's events only learns what the user did; the answer is the sink's state.
  // While another thread shows a frame, that call reads them.
  const std::unique_lock lock(xlib_, std::try_to_lock);
  if (lock.owns_lock()) {
    window_->handleEvents();
    open_ = window_->open();
  }
  return open_;
}

void X11WindowSink::finish(const cv::Mat& /*lastFrame*/, std::chrono::nanoseconds /*lastTime*/) {
  const std::lock_guard lock(xlib_);
  window_->handleEvents();
}

std::string X11WindowSink::describe() const {
  const std::lock_guard lock(xlib_);
  return fmt::format("window on {} ({} frames{})", window_->displayName(), framesShown_,
                     window_->stopReason());
}

unsigned long X11WindowSink::windowId() const {
  const std::lock_guard lock(xlib_);
  return window_->id();
}

bool X11WindowSink::sharedMemory() const {
  const std::lock_guard lock(xlib_);
  return window_->sharedMemory();
}

}  // namespace surroundd::render
