#include "render/dmabuf_import.hpp"

#include <algorithm>

#include <fmt/core.h>

#include "render/egl_context.hpp"

namespace surroundd::render {
namespace {

// DRM's format codes (drm_fourcc.h), in the byte order the textures hold: AB24 is R, G, B, A in
// memory (YUYV's Y0 U Y1 V as the upload's RGBA8), R8 one byte, GR88 R then G.
constexpr std::uint32_t fourcc(char a, char b, char c, char d) {
  return static_cast<std::uint32_t>(a) | static_cast<std::uint32_t>(b) << 8 |
         static_cast<std::uint32_t>(c) << 16 | static_cast<std::uint32_t>(d) << 24;
}
constexpr std::uint32_t kAbgr8888 = fourcc('A', 'B', '2', '4');
constexpr std::uint32_t kR8 = fourcc('R', '8', ' ', ' ');
constexpr std::uint32_t kGr88 = fourcc('G', 'R', '8', '8');

}  // namespace

DmabufImport::DmabufImport(PixelFormat format, cv::Size size)
    : format_(format), size_(size), display_(eglGetCurrentDisplay()) {
  kept_.reserve(kKept);
  if (format == PixelFormat::kBgr) {
    refusal_ = "BGR frames are not imported";
  } else if (!hasExtension(eglQueryString(display_, EGL_EXTENSIONS),
                           "EGL_EXT_image_dma_buf_import")) {
    refusal_ = "the EGL display cannot import DMABUFs (no EGL_EXT_image_dma_buf_import)";
  } else if (!gl::hasExtension("GL_OES_EGL_image")) {
    refusal_ = "OpenGL ES cannot take EGL images into textures (no GL_OES_EGL_image)";
  } else {
    createImage_ =
        reinterpret_cast<PFNEGLCREATEIMAGEKHRPROC>(eglGetProcAddress("eglCreateImageKHR"));
    destroyImage_ =
        reinterpret_cast<PFNEGLDESTROYIMAGEKHRPROC>(eglGetProcAddress("eglDestroyImageKHR"));
    targetTexture_ = reinterpret_cast<void (*)(GLenum, void*)>(
        eglGetProcAddress("glEGLImageTargetTexture2DOES"));
    if (createImage_ == nullptr || destroyImage_ == nullptr || targetTexture_ == nullptr) {
      refusal_ = "the EGL image functions cannot be found";
    }
  }
}

DmabufImport::~DmabufImport() {
  for (auto& imported : kept_) destroy(imported);
}

void DmabufImport::destroy(Imported& imported) {
  for (auto& image : imported.images) {
    if (image != EGL_NO_IMAGE_KHR) destroyImage_(display_, image);
    image = EGL_NO_IMAGE_KHR;
  }
}

template <typename Drop>
void DmabufImport::forget(Drop drop) {
  const auto gone =
      std::stable_partition(kept_.begin(), kept_.end(), [&](Imported& i) { return !drop(i); });
  for (auto it = gone; it != kept_.end(); ++it) destroy(*it);
  kept_.erase(gone, kept_.end());
}

std::optional<std::array<GLuint, 2>> DmabufImport::texturesOf(const DmabufPlanes& planes) {
  if (!refusal_.empty() || planes.planes == 0) return std::nullopt;
  const auto texturesIn = [&](const Imported& imported) {
    return std::array{imported.textures[0].name(),
                      planes.planes > 1 ? imported.textures[1].name() : 0};
  };
  const auto known = std::ranges::find(kept_, planes, &Imported::planes);
  if (known != kept_.end()) return texturesIn(*known);
  if (planes.session > session_) {
    session_ = planes.session;
    forget([&](const Imported& i) { return i.planes.session < session_; });
  }
  // The same buffer laid out otherwise (a driver may move a plane's start), or the oldest.
  forget([&](const Imported& i) {
    return i.planes.session == planes.session && i.planes.index == planes.index;
  });
  if (kept_.size() == kKept) {
    destroy(kept_.front());
    kept_.erase(kept_.begin());
  }
  Imported& imported = kept_.emplace_back();
  imported.planes = planes;
  if (!import(planes, imported)) {
    destroy(imported);
    kept_.pop_back();
    return std::nullopt;
  }
  return texturesIn(imported);
}

bool DmabufImport::import(const DmabufPlanes& planes, Imported& imported) {
  // An error left by earlier GL calls is not this import's. (A few flags at most; bounded, as a
  // lost context may answer with an error every time.)
  for (int flag = 0; flag < 8 && glGetError() != GL_NO_ERROR; ++flag) {
  }
  const bool nv12 = format_ == PixelFormat::kNv12;
  if (planes.planes != (nv12 ? 2U : 1U)) {
    refusal_ = fmt::format("a {} picture in {} planes", toString(format_), planes.planes);
    return false;
  }
  for (std::uint32_t p = 0; p < planes.planes; ++p) {
    const cv::Size size = !nv12    ? cv::Size(size_.width / 2, size_.height)
                          : p == 0 ? size_
                                   : cv::Size(size_.width / 2, size_.height / 2);
    const std::array<EGLint, 13> attributes{EGL_WIDTH,
                                            size.width,
                                            EGL_HEIGHT,
                                            size.height,
                                            EGL_LINUX_DRM_FOURCC_EXT,
                                            static_cast<EGLint>(!nv12    ? kAbgr8888
                                                                : p == 0 ? kR8
                                                                         : kGr88),
                                            EGL_DMA_BUF_PLANE0_FD_EXT,
                                            planes.fd[p],
                                            EGL_DMA_BUF_PLANE0_OFFSET_EXT,
                                            static_cast<EGLint>(planes.offset[p]),
                                            EGL_DMA_BUF_PLANE0_PITCH_EXT,
                                            static_cast<EGLint>(planes.pitch[p]),
                                            EGL_NONE};
    imported.images[p] =
        createImage_(display_, EGL_NO_CONTEXT, EGL_LINUX_DMA_BUF_EXT, nullptr, attributes.data());
    if (imported.images[p] == EGL_NO_IMAGE_KHR) {
      refusal_ =
          fmt::format("the driver refused to import a DMABUF (EGL error 0x{:x})", eglGetError());
      return false;
    }
    glBindTexture(GL_TEXTURE_2D, imported.textures[p].name());
    targetTexture_(GL_TEXTURE_2D, imported.images[p]);
    // One level, read with texelFetch: without these the texture is incomplete and reads black.
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    if (const GLenum error = glGetError(); error != GL_NO_ERROR) {
      refusal_ = fmt::format("OpenGL ES refused an imported DMABUF (GL error 0x{:x})", error);
      return false;
    }
  }
  return true;
}

}  // namespace surroundd::render
