#pragma once
// An OpenGL ES 3 context through EGL, for rendering into framebuffer objects: headless, no
// display server. Platforms, in the order `kAuto` tries them:
//   device       EGL_EXT_platform_device on a hardware device (NVIDIA's driver, or a DRM node);
//   surfaceless  EGL_MESA_platform_surfaceless (Mesa: a GPU, or llvmpipe on the CPU);
//   default      the default display with a 1x1 pbuffer, for drivers with neither.
// And, asked for by name only, where it can also draw into what a display shows:
//   x11          on an X server's connection (EGL_KHR_platform_x11): also into that server's
//                windows (render/outputs/egl_window_sink.hpp);
//   gbm          on a GBM device of a DRM card (EGL_KHR_platform_gbm): also into GBM surfaces,
//                whose buffers the card scans out (render/outputs/egl_display_sink.hpp).
// The context is current on the thread that made it until release() hands it on, and then on
// the one that calls makeCurrent(): EGL binds a context to one thread at a time, so GL objects are
// made and used on the thread that has it, and destroyed before the context.

#include <memory>
#include <string>
#include <string_view>

#include <EGL/egl.h>

namespace surroundd::render {

enum class EglPlatform { kAuto, kDevice, kSurfaceless, kDefault, kX11, kGbm };

class EglContext {
 public:
  // Throws RenderError listing each platform tried and why it failed. kX11 and kGbm need
  // `nativeDisplay` (an Xlib Display*, a gbm_device*), open longer than the context;
  // `nativeOwner`, when given, keeps it open and is released once the context is closed.
  explicit EglContext(EglPlatform platform = EglPlatform::kAuto, void* nativeDisplay = nullptr,
                      std::shared_ptr<void> nativeOwner = nullptr);
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  // "surfaceless: llvmpipe (LLVM 15.0.6, 256 bits), OpenGL ES 3.2 Mesa 22.3.6"
  const std::string& description() const { return description_; }
  // Current on no thread from now on (called on the thread that has it), so that another can
  // take it.
  void release();
  // Current on the calling thread; no other may have it. Throws RenderError.
  void makeCurrent();
  EglPlatform platform() const { return platform_; }
  // For surfaces of the context's display (kX11: windows; kGbm: GBM surfaces, XRGB8888): its
  // display and configuration, and the native display it is on (null on the headless ones).
  EGLDisplay display() const { return display_; }
  EGLConfig config() const { return config_; }
  void* nativeDisplay() const { return nativeDisplay_; }
  // Draws into `surface`'s default framebuffer from now on (EGL_NO_SURFACE: none, only into
  // framebuffer objects, as after construction), on the thread that has the context. Throws
  // RenderError.
  void drawInto(EGLSurface surface);
  // Whether the renderer runs on the CPU (Mesa's llvmpipe, softpipe or swrast; SwiftShader):
  // there, pixel work is faster in the CPU path than through OpenGL.
  bool software() const { return software_; }

 private:
  bool open(EglPlatform platform, void* nativeDisplay, std::string& why);
  void close();

  std::shared_ptr<void> nativeOwner_;  // released after close(): declared first
  void* nativeDisplay_ = nullptr;
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLConfig config_ = nullptr;
  EGLContext context_ = EGL_NO_CONTEXT;
  EGLSurface surface_ = EGL_NO_SURFACE;  // only for the default platform
  EglPlatform platform_ = EglPlatform::kAuto;
  std::string description_;
  bool software_ = false;
};

const char* toString(EglPlatform platform);

// Whether an extension list (eglQueryString(display, EGL_EXTENSIONS)) names `name`.
bool hasExtension(const char* list, std::string_view name);

// Whether the renderer of the context current on this thread runs on the CPU (as
// EglContext::software() says of its own).
bool softwareRenderer();

}  // namespace surroundd::render
