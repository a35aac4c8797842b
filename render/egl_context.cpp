#include "render/egl_context.hpp"

#include <algorithm>
#include <array>
#include <string_view>
#include <utility>
#include <vector>

#include <EGL/eglext.h>
#include <GLES3/gl3.h>
#include <fmt/core.h>

#include "render/render_error.hpp"

namespace surroundd::render {

bool hasExtension(const char* list, std::string_view name) {
  if (list == nullptr) return false;
  const std::string_view all(list);
  for (std::size_t at = all.find(name); at != std::string_view::npos; at = all.find(name, at + 1)) {
    const bool startsWord = at == 0 || all[at - 1] == ' ';
    const std::size_t end = at + name.size();
    if (startsWord && (end == all.size() || all[end] == ' ')) return true;
  }
  return false;
}

namespace {

// GL_RENDERER of the renderers that run on the CPU.
constexpr std::array<std::string_view, 4> kSoftwareRenderers{"llvmpipe", "softpipe", "swrast",
                                                             "SwiftShader"};

std::string eglErrorText(std::string_view call) {
  return fmt::format("{} failed (EGL error 0x{:04x})", call, eglGetError());
}

template <typename Function>
Function procedure(const char* name) {
  return reinterpret_cast<Function>(eglGetProcAddress(name));
}

// The first hardware EGL device's display; software devices (Mesa's llvmpipe) are left to the
// surfaceless platform, which is Mesa's own.
EGLDisplay deviceDisplay(std::string& why) {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!hasExtension(client, "EGL_EXT_platform_device") ||
      !hasExtension(client, "EGL_EXT_device_enumeration")) {
    why = "the EGL client has no EGL_EXT_platform_device";
    return EGL_NO_DISPLAY;
  }
  const auto queryDevices = procedure<PFNEGLQUERYDEVICESEXTPROC>("eglQueryDevicesEXT");
  const auto queryDeviceString =
      procedure<PFNEGLQUERYDEVICESTRINGEXTPROC>("eglQueryDeviceStringEXT");
  const auto platformDisplay =
      procedure<PFNEGLGETPLATFORMDISPLAYEXTPROC>("eglGetPlatformDisplayEXT");
  std::array<EGLDeviceEXT, 16> devices{};
  EGLint count = 0;
  if (queryDevices == nullptr || platformDisplay == nullptr || queryDeviceString == nullptr ||
      queryDevices(static_cast<EGLint>(devices.size()), devices.data(), &count) != EGL_TRUE) {
    why = eglErrorText("eglQueryDevicesEXT");
    return EGL_NO_DISPLAY;
  }
  for (EGLint i = 0; i < count; ++i) {
    if (hasExtension(queryDeviceString(devices[i], EGL_EXTENSIONS), "EGL_MESA_device_software")) {
      continue;
    }
    const EGLDisplay display = platformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
    if (display != EGL_NO_DISPLAY) return display;
  }
  why = fmt::format("none of {} EGL device(s) is a hardware device", count);
  return EGL_NO_DISPLAY;
}

EGLDisplay surfacelessDisplay(std::string& why) {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!hasExtension(client, "EGL_MESA_platform_surfaceless")) {
    why = "the EGL client has no EGL_MESA_platform_surfaceless";
    return EGL_NO_DISPLAY;
  }
  const auto platformDisplay =
      procedure<PFNEGLGETPLATFORMDISPLAYEXTPROC>("eglGetPlatformDisplayEXT");
  const EGLDisplay display =
      platformDisplay != nullptr
          ? platformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr)
          : EGL_NO_DISPLAY;
  if (display == EGL_NO_DISPLAY) why = eglErrorText("eglGetPlatformDisplayEXT(surfaceless)");
  return display;
}

// The display on a native one, `native` (an X display, a GBM device): `platform` is the
// EGL_PLATFORM_* enum of `extension`.
EGLDisplay nativePlatformDisplay(EGLenum platform, std::string_view extension,
                                 std::string_view native, void* nativeDisplay, std::string& why) {
  if (nativeDisplay == nullptr) {
    why = fmt::format("no {} given", native);
    return EGL_NO_DISPLAY;
  }
  if (!hasExtension(eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS), extension)) {
    why = fmt::format("the EGL client has no {}", extension);
    return EGL_NO_DISPLAY;
  }
  const auto platformDisplay =
      procedure<PFNEGLGETPLATFORMDISPLAYEXTPROC>("eglGetPlatformDisplayEXT");
  const EGLDisplay display = platformDisplay != nullptr
                                 ? platformDisplay(platform, nativeDisplay, nullptr)
                                 : EGL_NO_DISPLAY;
  if (display == EGL_NO_DISPLAY)
    why = eglErrorText(fmt::format("eglGetPlatformDisplayEXT({})", extension));
  return display;
}

// DRM's XRGB8888 as a GBM surface's format and an EGL configuration's native visual id: what a
// display controller scans out everywhere.
constexpr EGLint kXrgb8888 = 'X' | ('R' << 8) | ('2' << 16) | ('4' << 24);

// An RGB8 OpenGL ES 3 configuration: with alpha for framebuffer objects and windows; on GBM, the
// one whose buffers are XRGB8888, for the screen.
bool chooseConfig(EGLDisplay display, EglPlatform platform, EGLConfig& config) {
  const bool gbm = platform == EglPlatform::kGbm;
  EGLint surfaces = EGL_PBUFFER_BIT;
  // On X11 also windows; a pbuffer stays possible for drivers without surfaceless contexts.
  if (platform == EglPlatform::kX11) surfaces = EGL_WINDOW_BIT | EGL_PBUFFER_BIT;
  if (gbm) surfaces = EGL_WINDOW_BIT;
  const std::array<EGLint, 13> attributes{
      EGL_SURFACE_TYPE, surfaces, EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT,
      EGL_RED_SIZE,     8,        EGL_GREEN_SIZE,      8,
      EGL_BLUE_SIZE,    8,        EGL_ALPHA_SIZE,      gbm ? 0 : 8,
      EGL_NONE};
  std::array<EGLConfig, 64> configs{};
  EGLint count = 0;
  if (eglChooseConfig(display, attributes.data(), configs.data(),
                      static_cast<EGLint>(configs.size()), &count) != EGL_TRUE) {
    return false;
  }
  for (EGLint i = 0; i < count; ++i) {
    EGLint visual = 0;
    if (!gbm ||
        (eglGetConfigAttrib(display, configs[i], EGL_NATIVE_VISUAL_ID, &visual) == EGL_TRUE &&
         visual == kXrgb8888)) {
      config = configs[i];
      return true;
    }
  }
  return false;
}

}  // namespace

bool softwareRenderer() {
  const auto* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  if (name == nullptr) return false;
  const std::string_view renderer(name);
  return std::ranges::any_of(kSoftwareRenderers, [&](std::string_view software) {
    return renderer.find(software) != std::string_view::npos;
  });
}

const char* toString(EglPlatform platform) {
  switch (platform) {
    case EglPlatform::kAuto:
      return "auto";
    case EglPlatform::kDevice:
      return "device";
    case EglPlatform::kSurfaceless:
      return "surfaceless";
    case EglPlatform::kDefault:
      return "default";
    case EglPlatform::kX11:
      return "x11";
    case EglPlatform::kGbm:
      return "gbm";
  }
  return "?";
}

EglContext::EglContext(EglPlatform platform, void* nativeDisplay, std::shared_ptr<void> nativeOwner)
    : nativeOwner_(std::move(nativeOwner)) {
  const std::vector<EglPlatform> order =
      platform == EglPlatform::kAuto
          ? std::vector{EglPlatform::kDevice, EglPlatform::kSurfaceless, EglPlatform::kDefault}
          : std::vector{platform};
  std::string failures;
  for (const EglPlatform candidate : order) {
    std::string why;
    if (open(candidate, nativeDisplay, why)) return;
    close();
    failures += fmt::format("; {}: {}", toString(candidate), why);
  }
  throw RenderError("no OpenGL ES 3 context through EGL" + failures);
}

EglContext::~EglContext() { close(); }

bool EglContext::open(EglPlatform platform, void* nativeDisplay, std::string& why) {
  if (platform == EglPlatform::kDevice) display_ = deviceDisplay(why);
  if (platform == EglPlatform::kX11) {
    display_ = nativePlatformDisplay(EGL_PLATFORM_X11_KHR, "EGL_KHR_platform_x11", "X display",
                                     nativeDisplay, why);
  }
  if (platform == EglPlatform::kGbm) {
    display_ = nativePlatformDisplay(EGL_PLATFORM_GBM_KHR, "EGL_KHR_platform_gbm", "GBM device",
                                     nativeDisplay, why);
  }
  if (platform == EglPlatform::kSurfaceless) display_ = surfacelessDisplay(why);
  if (platform == EglPlatform::kDefault) {
    display_ = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    if (display_ == EGL_NO_DISPLAY) why = eglErrorText("eglGetDisplay");
  }
  if (display_ == EGL_NO_DISPLAY) return false;
  EGLint major = 0;
  EGLint minor = 0;
  if (eglInitialize(display_, &major, &minor) != EGL_TRUE) {
    why = eglErrorText("eglInitialize");
    display_ = EGL_NO_DISPLAY;  // nothing to terminate
    return false;
  }
  if (eglBindAPI(EGL_OPENGL_ES_API) != EGL_TRUE) {
    why = eglErrorText("eglBindAPI(OpenGL ES)");
    return false;
  }
  if (!chooseConfig(display_, platform, config_)) {
    why = platform == EglPlatform::kGbm ? "no OpenGL ES 3 configuration for XRGB8888 buffers"
                                        : "no RGBA8 OpenGL ES 3 configuration";
    return false;
  }
  const std::array<EGLint, 5> contextAttributes{EGL_CONTEXT_MAJOR_VERSION, 3,
                                                EGL_CONTEXT_MINOR_VERSION, 0, EGL_NONE};
  context_ = eglCreateContext(display_, config_, EGL_NO_CONTEXT, contextAttributes.data());
  if (context_ == EGL_NO_CONTEXT) {
    why = eglErrorText("eglCreateContext(OpenGL ES 3.0)");
    return false;
  }
  // Rendering goes to framebuffer objects; a surface is only needed where the driver lacks
  // EGL_KHR_surfaceless_context.
  if (!hasExtension(eglQueryString(display_, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context")) {
    const std::array<EGLint, 5> pbuffer{EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
    surface_ = eglCreatePbufferSurface(display_, config_, pbuffer.data());
    if (surface_ == EGL_NO_SURFACE) {
      why = eglErrorText("eglCreatePbufferSurface");
      return false;
    }
  }
  if (eglMakeCurrent(display_, surface_, surface_, context_) != EGL_TRUE) {
    why = eglErrorText("eglMakeCurrent");
    return false;
  }
  platform_ = platform;
  nativeDisplay_ = nativeDisplay;
  software_ = softwareRenderer();
  description_ = fmt::format("{}: {}, {}", toString(platform),
                             reinterpret_cast<const char*>(glGetString(GL_RENDERER)),
                             reinterpret_cast<const char*>(glGetString(GL_VERSION)));
  return true;
}

void EglContext::release() {
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
}

void EglContext::makeCurrent() {
  if (eglMakeCurrent(display_, surface_, surface_, context_) != EGL_TRUE) {
    throw RenderError(eglErrorText("eglMakeCurrent"));
  }
}

void EglContext::drawInto(EGLSurface surface) {
  const EGLSurface target = surface == EGL_NO_SURFACE ? surface_ : surface;
  if (eglMakeCurrent(display_, target, target, context_) != EGL_TRUE) {
    throw RenderError(eglErrorText("eglMakeCurrent(surface)"));
  }
}

void EglContext::close() {
  if (display_ == EGL_NO_DISPLAY) return;
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
  if (surface_ != EGL_NO_SURFACE) eglDestroySurface(display_, surface_);
  eglTerminate(display_);
  display_ = EGL_NO_DISPLAY;
  context_ = EGL_NO_CONTEXT;
  surface_ = EGL_NO_SURFACE;
  config_ = nullptr;
}

}  // namespace surroundd::render
