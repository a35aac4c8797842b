#include "render/outputs/egl_window.hpp"

#include <memory>

#include <EGL/eglext.h>
#include <GLES3/gl3.h>
#include <fmt/format.h>

#include "render/gl_objects.hpp"
#include "render/outputs/xlib_window.hpp"  // after every other header: Xlib's macros
#include "render/render_error.hpp"

namespace surroundd::render {
namespace {

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

// The window and the EGL surface that draws into it; the surface goes first, when the window
// closes or is destroyed.
class EglWindow::Surface {
 public:
  Surface(EglContext& gl, XlibDisplay& display, const X11WindowSettings& settings)
      : gl_(gl), window_(display, configVisual(gl, display), settings.title, settings.size, [this] {
          release();
        }) {
    if (!window_.open()) return;
    ::Window id = window_.id();
    surface_ = eglCreatePlatformWindowSurface(gl_.display(), gl_.config(), &id, nullptr);
    if (surface_ == EGL_NO_SURFACE) {
      throw RenderError(
          fmt::format("EGL window on {}: eglCreatePlatformWindowSurface failed (EGL "
                      "error 0x{:04x})",
                      display.name(), eglGetError()));
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

  XlibWindow& window() { return window_; }
  const XlibWindow& window() const { return window_; }
  EGLSurface get() const { return surface_; }

 private:
  void release() {
    if (surface_ != EGL_NO_SURFACE) eglDestroySurface(gl_.display(), surface_);
    surface_ = EGL_NO_SURFACE;
  }

  EglContext& gl_;
  EGLSurface surface_ = EGL_NO_SURFACE;
  XlibWindow window_;
};

EglWindow::EglWindow(EglContext& gl, XlibDisplay& display, const X11WindowSettings& settings)
    : gl_(gl), size_(settings.size) {
  if (gl.platform() != EglPlatform::kX11) {
    throw RenderError(fmt::format(
        "EGL window on {}: the renderer's context is on the {} platform, not on the X server's",
        display.name(), toString(gl.platform())));
  }
  if (size_.width <= 0 || size_.height <= 0) {
    throw RenderError(fmt::format("EGL window on {}: the size must be positive, got {}x{}",
                                  display.name(), size_.width, size_.height));
  }
  surface_ = std::make_unique<Surface>(gl, display, settings);
}

EglWindow::~EglWindow() = default;

bool EglWindow::present(const SurroundView& view) {
  XlibWindow& window = surface_->window();
  if (view.size() != size_) {
    throw RenderError(fmt::format("EGL window on {}: the view is {}x{}, the window {}x{}",
                                  window.display().name(), view.size().width, view.size().height,
                                  size_.width, size_.height));
  }
  // An uncovered window shows the next picture: the views are drawn at the cameras' rate.
  window.handleEvents();
  if (!window.open()) return false;
  gl_.drawInto(surface_->get());
  glBindFramebuffer(GL_READ_FRAMEBUFFER, view.framebuffer());
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  // The view's row 0 is the picture's top, the window's the bottom.
  glBlitFramebuffer(0, 0, size_.width, size_.height, 0, size_.height, size_.width, 0,
                    GL_COLOR_BUFFER_BIT, GL_NEAREST);
  const bool swapped = eglSwapBuffers(gl_.display(), surface_->get()) == EGL_TRUE;
  const EGLint swapError = swapped ? EGL_SUCCESS : eglGetError();
  gl_.drawInto(EGL_NO_SURFACE);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  gl::check("showing a view in a window");
  // On the screen when this returns, as X11WindowSink's frames, and the server's errors seen.
  window.display().sync("showing a view");
  if (window.display().lost()) window.close(XlibWindow::State::kDisplayLost);
  if (!window.open()) return false;
  if (!swapped) {
    throw RenderError(fmt::format("EGL window on {}: eglSwapBuffers failed (EGL error 0x{:04x})",
                                  window.display().name(), swapError));
  }
  ++framesShown_;
  return true;
}

bool EglWindow::open() const { return surface_->window().open(); }

unsigned long EglWindow::windowId() const { return surface_->window().id(); }

std::string EglWindow::describe() const {
  const XlibWindow& window = surface_->window();
  return fmt::format("EGL window on {} ({} frames{})", window.display().name(), framesShown_,
                     window.stopReason());
}

}  // namespace surroundd::render
