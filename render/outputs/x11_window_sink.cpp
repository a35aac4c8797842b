#include "render/outputs/x11_window_sink.hpp"

#include <string_view>
#include <type_traits>
#include <utility>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "render/render_error.hpp"

// After every other header: Xlib's macros.
#include "render/outputs/xlib_display.hpp"
#include "render/outputs/xlib_image.hpp"
#include "render/outputs/xlib_window.hpp"

namespace surroundd::render {
namespace {

XVisualInfo trueColorVisual(XlibDisplay& display) {
  XVisualInfo visual{};
  if (XMatchVisualInfo(display.get(), DefaultScreen(display.get()), 24, TrueColor, &visual) == 0) {
    throw RenderError(fmt::format("X11 window on {}: the display has no 24-bit TrueColor visual",
                                  display.name()));
  }
  return visual;
}

struct GcDeleter {
  Display* display;
  // Also frees the GC's client-side memory, so it runs even on a lost connection.
  void operator()(GC gc) const { XFreeGC(display, gc); }
};

}  // namespace

// The X connection, the window and the picture it shows. The picture and GC are made once the
// window is, and freed just before it when it closes; declared before it, so that they are there,
// empty, should it close while it opens.
class X11WindowSink::ShownWindow {
 public:
  explicit ShownWindow(const X11WindowSettings& settings);

  // Shows `bgr` (8-bit BGR of the window's size); false when the display went away meanwhile.
  bool show(const cv::Mat& bgr);
  // Handles the events that arrived (close, expose) without waiting for more.
  void handleEvents();

  bool open() const { return window_.open(); }
  const std::string& displayName() const { return display_.name(); }
  ::Window id() const { return window_.id(); }
  bool sharedMemory() const { return image_ && image_->sharedMemory(); }
  std::string_view stopReason() const { return window_.stopReason(); }

 private:
  XlibDisplay display_;
  XVisualInfo visual_;
  std::unique_ptr<std::remove_pointer_t<GC>, GcDeleter> gc_{nullptr, GcDeleter{display_.get()}};
  std::unique_ptr<XlibImage> image_;
  bool hasPicture_ = false;
  bool redrawInFlight_ = false;  // an Expose redraw the server may still be reading image_ for
  XlibWindow window_;
};

X11WindowSink::ShownWindow::ShownWindow(const X11WindowSettings& settings)
    : display_(settings.display),
      visual_(trueColorVisual(display_)),
      window_(display_, visual_, settings.title, settings.size, [this] {
        image_.reset();
        gc_.reset();
        redrawInFlight_ = false;
      }) {
  if (!window_.open()) return;
  gc_.reset(XCreateGC(display_.get(), window_.id(), 0, nullptr));
  image_ = std::make_unique<XlibImage>(display_, visual_, settings.size);
  display_.sync("making the window's picture");
}

void X11WindowSink::ShownWindow::handleEvents() {
  // Redraw once per series of exposed rectangles; the next show() waits for it to finish.
  if (window_.handleEvents() && hasPicture_) {
    image_->put(window_.id(), gc_.get());
    XFlush(display_.get());
    redrawInFlight_ = true;
  }
}

bool X11WindowSink::ShownWindow::show(const cv::Mat& bgr) {
  if (redrawInFlight_) {
    display_.sync("redrawing the window");
    redrawInFlight_ = false;
  }
  // The const header has a fixed size and type: cvtColor writes into the image's memory and would
  // throw rather than allocate.
  cv::cvtColor(bgr, image_->pixels(), cv::COLOR_BGR2BGRA);
  image_->put(window_.id(), gc_.get());
  display_.sync("showing a frame");
  hasPicture_ = true;
  if (display_.lost()) window_.close(XlibWindow::State::kDisplayLost);
  return open();
}

X11WindowSink::X11WindowSink(X11WindowSettings settings) : settings_(std::move(settings)) {
  if (settings_.size.width <= 0 || settings_.size.height <= 0) {
    throw RenderError(fmt::format("X11 window: the size must be positive, got {}x{}",
                                  settings_.size.width, settings_.size.height));
  }
  window_ = std::make_unique<ShownWindow>(settings_);
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
