#include "render/outputs/egl_window_sink.hpp"

#include <memory>
#include <utility>

#include <EGL/eglext.h>
#include <GLES3/gl3.h>
#include <fmt/format.h>

#include "render/outputs/view_blit.hpp"
#include "render/render_error.hpp"
#include "render/surround_view.hpp"

// After every other header: Xlib's macros.
#include "render/outputs/xlib_window.hpp"

namespace surroundd::render {
namespace {

std::string eglFailure(const XlibDisplay& display, std::string_view call) {
  return fmt::format("EGL window on {}: {} failed (EGL error 0x{:04x})", display.name(), call,
                     eglGetError());
}

// The X visual of the context's configuration: a window surface needs a window of it.
XVisualInfo configVisual(const EglContext& gl, XlibDisplay& display) {
  EGLint id = 0;
  if (eglGetConfigAttrib(gl.display(), gl.config(), EGL_NATIVE_VISUAL_ID, &id) != EGL_TRUE ||
      id == 0) {
    throw RenderError(fmt::format("EGL window on {}: the renderer's configuration has no X visual",
                                  display.name()));
  }
  XVisualInfo wanted{};
  wanted.visualid = static_cast<VisualID>(id);
  int count = 0;
  const std::unique_ptr<XVisualInfo, int (*)(void*)> found(
      XGetVisualInfo(display.get(), VisualIDMask, &wanted, &count), &XFree);
  if (found == nullptr || count == 0) {
    throw RenderError(
        fmt::format("EGL window on {}: the display has no visual 0x{:x}", display.name(), id));
  }
  return *found;
}

}  // namespace

// The window's connection, the window, and the EGL surface that draws into it; the surface goes
// first, when the window closes or is destroyed.
class EglWindowSink::Surface {
 public:
  Surface(EglContext& gl, const X11WindowSettings& settings)
      : gl_(gl),
        display_(settings.display),
        window_(display_, configVisual(gl, display_), settings.title, settings.size,
                [this] { release(); }) {
    if (!window_.open()) return;
    ::Window id = window_.id();
    surface_ = eglCreatePlatformWindowSurface(gl_.display(), gl_.config(), &id, nullptr);
    if (surface_ == EGL_NO_SURFACE) {
      throw RenderError(eglFailure(display_, "eglCreatePlatformWindowSurface"));
    }
    // A picture goes to the screen as it is drawn: a display that waits for the vertical blank
    // would hold the renderer's thread, and every other output's view with it.
    gl_.drawInto(surface_);
    eglSwapInterval(gl_.display(), 0);
    gl_.drawInto(EGL_NO_SURFACE);
  }
  ~Surface() { release(); }
  Surface(const Surface&) = delete;
  Surface& operator=(const Surface&) = delete;

  // Blits `framebuffer` (row 0 the picture's top) of `size` into the window and swaps.
  void show(GLuint framebuffer, cv::Size size) {
    gl_.drawInto(surface_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    blitView(framebuffer, size, size);
    const bool swapped = eglSwapBuffers(gl_.display(), surface_) == EGL_TRUE;
    const std::string failure = swapped ? "" : eglFailure(display_, "eglSwapBuffers");
    gl_.drawInto(EGL_NO_SURFACE);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    // No round trip to wait for the server here: the renderer's thread goes on while the server
    // puts the picture on the screen (the swap's requests go through the renderer's connection).
    // A lost server shows in the window's events, read before each picture.
    if (!swapped && window_.open()) throw RenderError(failure);
  }

  XlibDisplay& display() { return display_; }
  const XlibDisplay& display() const { return display_; }
  XlibWindow& window() { return window_; }
  const XlibWindow& window() const { return window_; }

 private:
  void release() {
    if (surface_ != EGL_NO_SURFACE) eglDestroySurface(gl_.display(), surface_);
    surface_ = EGL_NO_SURFACE;
  }

  EglContext& gl_;
  XlibDisplay display_;
  EGLSurface surface_ = EGL_NO_SURFACE;
  XlibWindow window_;
};

EglWindowSink::EglWindowSink(EglContext& gl, X11WindowSettings settings)
    : gl_(gl), settings_(std::move(settings)) {
  if (gl.platform() != EglPlatform::kX11) {
    throw RenderError(fmt::format(
        "EGL window on {}: the renderer's context is on the {} platform, not on an X server's",
        settings_.display.empty() ? "$DISPLAY" : settings_.display, toString(gl.platform())));
  }
  if (settings_.size.width <= 0 || settings_.size.height <= 0) {
    throw RenderError(fmt::format("EGL window: the size must be positive, got {}x{}",
                                  settings_.size.width, settings_.size.height));
  }
  surface_ = std::make_unique<Surface>(gl, settings_);
}

EglWindowSink::~EglWindowSink() = default;

void EglWindowSink::present(const SurroundView& view, const PictureTime& /*time*/) {
  if (view.size() != settings_.size) {
    throw RenderError(fmt::format("EGL window on {}: the view is {}x{}, the window {}x{}",
                                  surface_->display().name(), view.size().width, view.size().height,
                                  settings_.size.width, settings_.size.height));
  }
  // An uncovered window shows the next picture: the views are drawn at the cameras' rate.
  surface_->window().handleEvents();
  if (!surface_->window().open()) return;
  surface_->show(view.framebuffer(), settings_.size);
  if (surface_->window().open()) ++framesShown_;
}

void EglWindowSink::consume(const cv::Mat& /*picture*/, const PictureTime& /*time*/) {
  throw RenderError(fmt::format(
      "EGL window on {}: it shows surround views drawn by OpenGL, not pictures of another stream",
      surface_->display().name()));
}

bool EglWindowSink::wantsFrame(std::chrono::nanoseconds /*streamTime*/) const {
  surface_->window().handleEvents();
  return surface_->window().open();
}

void EglWindowSink::finish(const cv::Mat& /*lastFrame*/, std::chrono::nanoseconds /*lastTime*/) {
  surface_->window().handleEvents();
}

std::string EglWindowSink::describe() const {
  return fmt::format("EGL window on {} ({} frames{})", surface_->display().name(), framesShown_,
                     surface_->window().stopReason());
}

unsigned long EglWindowSink::windowId() const { return surface_->window().id(); }

}  // namespace surroundd::render
