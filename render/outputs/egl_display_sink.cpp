#include "render/outputs/egl_display_sink.hpp"

#include <cstdlib>
#include <filesystem>
#include <utility>

#include <EGL/eglext.h>
#include <GLES3/gl3.h>
#include <fmt/format.h>
#include <gbm.h>
#include <xf86drm.h>

#include "render/outputs/view_blit.hpp"
#include "render/render_error.hpp"
#include "render/surround_view.hpp"

namespace surroundd::render {
namespace {

// The card node a GBM device is on, for messages: "/dev/dri/card0".
std::filesystem::path cardOf(gbm_device* device) {
  const std::unique_ptr<char, decltype(&std::free)> name(
      drmGetDeviceNameFromFd2(gbm_device_get_fd(device)), &std::free);
  return name != nullptr ? std::filesystem::path(name.get()) : std::filesystem::path("a DRM card");
}

}  // namespace

class EglDisplaySink::Surface {
 public:
  Surface(EglContext& gl, gbm_device* device, cv::Size size, std::string name)
      : gl_(gl), name_(std::move(name)) {
    surface_ = gbm_surface_create(device, size.width, size.height, GBM_FORMAT_XRGB8888,
                                  GBM_BO_USE_SCANOUT | GBM_BO_USE_RENDERING);
    if (surface_ == nullptr) {
      throw RenderError(
          fmt::format("{}: cannot create a {}x{} GBM surface", name_, size.width, size.height));
    }
    egl_ = eglCreatePlatformWindowSurface(gl.display(), gl.config(), surface_, nullptr);
    if (egl_ == EGL_NO_SURFACE) {
      gbm_surface_destroy(surface_);
      throw RenderError(fmt::format(
          "{}: eglCreatePlatformWindowSurface failed (EGL error 0x{:04x})", name_, eglGetError()));
    }
  }
  ~Surface() {
    for (gbm_bo* bo : {shown_, previous_}) {
      if (bo != nullptr) gbm_surface_release_buffer(surface_, bo);
    }
    eglDestroySurface(gl_.display(), egl_);
    gbm_surface_destroy(surface_);
  }
  Surface(const Surface&) = delete;
  Surface& operator=(const Surface&) = delete;

  // Draws `view` fitted into the surface's next buffer and locks it for the screen: the buffer
  // to show.
  gbm_bo* draw(const SurroundView& view, cv::Size size) {
    gl_.drawInto(egl_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    blitView(view.framebuffer(), view.size(), size);
    const bool swapped = eglSwapBuffers(gl_.display(), egl_) == EGL_TRUE;
    const EGLint error = eglGetError();
    gl_.drawInto(EGL_NO_SURFACE);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (!swapped) {
      throw RenderError(
          fmt::format("{}: eglSwapBuffers failed (EGL error 0x{:04x})", name_, error));
    }
    gbm_bo* next = gbm_surface_lock_front_buffer(surface_);
    if (next == nullptr) throw RenderError(fmt::format("{}: no buffer to show", name_));
    return next;
  }

  // `bo` is on the screen, or will be from the next vertical blank.
  void shown(gbm_bo* bo) { previous_ = std::exchange(shown_, bo); }
  // The buffer the screen showed before the last one goes back to the surface for drawing, once
  // the flip away from it has completed.
  void releasePrevious() {
    if (previous_ != nullptr) gbm_surface_release_buffer(surface_, previous_);
    previous_ = nullptr;
  }

 private:
  EglContext& gl_;
  std::string name_;
  gbm_surface* surface_ = nullptr;
  EGLSurface egl_ = EGL_NO_SURFACE;
  gbm_bo* shown_ = nullptr;
  gbm_bo* previous_ = nullptr;
};

EglDisplaySink::EglDisplaySink(EglContext& gl, const std::string& connector) : gl_(gl) {
  if (gl.platform() != EglPlatform::kGbm) {
    throw RenderError(
        fmt::format("EGL display: the renderer's context is on the {} platform, not on a DRM "
                    "card's GBM device",
                    toString(gl.platform())));
  }
  auto* device = static_cast<gbm_device*>(gl.nativeDisplay());
  const std::filesystem::path card = cardOf(device);
  auto screen = std::make_unique<KmsScreen>(gbm_device_get_fd(device), card, connector);
  surface_ = std::make_unique<Surface>(gl, device, screen->size(),
                                       fmt::format("EGL display {}", screen->describe()));
  screen_ = std::move(screen);
}

EglDisplaySink::~EglDisplaySink() = default;

void EglDisplaySink::present(const SurroundView& view, const PictureTime& /*time*/) {
  if (!screen_->flipped()) {
    ++framesNotShown_;
    return;
  }
  surface_->releasePrevious();
  gbm_bo* next = surface_->draw(view, screen_->size());
  screen_->show(screen_->framebufferOf(next));
  surface_->shown(next);
  ++framesShown_;
}

void EglDisplaySink::consume(const cv::Mat& /*picture*/, const PictureTime& /*time*/) {
  throw RenderError(fmt::format(
      "EGL display {}: it shows surround views drawn by OpenGL, not pictures of another stream",
      screen_->describe()));
}

void EglDisplaySink::finish(const cv::Mat& /*lastFrame*/, std::chrono::nanoseconds /*lastTime*/) {
  screen_->finishFlip();
}

std::string EglDisplaySink::describe() const {
  return fmt::format(
      "EGL display {} ({} frames{})", screen_->describe(), framesShown_,
      framesNotShown_ == 0
          ? ""
          : fmt::format(", {} not shown: the screen was still flipping", framesNotShown_));
}

}  // namespace surroundd::render
