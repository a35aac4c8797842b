#pragma once
// Camera pictures taken into textures straight from the DMABUFs they lie in
// (EGL_EXT_image_dma_buf_import and GL_OES_EGL_image): no copy by the CPU, no upload. Each buffer
// is imported once, an EGLImage of each plane bound to a texture, in the layouts CameraTexture's
// uploads have (YUYV and UYVY: four-byte texels of half the width; NV12: one-byte luma, two-byte
// chroma of half the width and height), so that the stitch samples either the same way. Imports
// are kept under the buffer's name and layout (DmabufPlanes), the last kKept of them: the buffers
// a camera cycles through are imported once. An import holds its buffer's memory, so those of a
// streaming session are let go as soon as a later session's buffer comes (the camera was reopened:
// the driver has freed the old buffers, but for the references imports hold).
//
// Set-up and use on the thread of the current EglContext; texturesOf() allocates only when it
// imports a buffer it has not seen.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <opencv2/core.hpp>

#include "common/dmabuf_planes.hpp"
#include "common/pixel_format.hpp"
#include "render/gl_objects.hpp"

namespace surroundd::render {

class DmabufImport {
 public:
  static constexpr std::size_t kKept = 32;

  // For pictures of `format` and `size` (even).
  DmabufImport(PixelFormat format, cv::Size size);
  ~DmabufImport();
  DmabufImport(const DmabufImport&) = delete;
  DmabufImport& operator=(const DmabufImport&) = delete;

  // Why pictures are not imported here: the display or the GL lacks the extension, the format is
  // BGR, or the driver refused a buffer (and the rest are not tried). Empty while they are.
  const std::string& refusal() const { return refusal_; }
  // The textures holding the picture: its pixels (or luma) and its chroma (or 0), imported the
  // first time its buffer is seen; nullopt, with refusal() saying why, when it cannot be.
  std::optional<std::array<GLuint, 2>> texturesOf(const DmabufPlanes& planes);
  // How many buffers are imported now.
  std::size_t imports() const { return kept_.size(); }

 private:
  struct Imported {
    DmabufPlanes planes;
    std::array<EGLImageKHR, 2> images{EGL_NO_IMAGE_KHR, EGL_NO_IMAGE_KHR};
    std::array<gl::Texture, 2> textures;
  };
  bool import(const DmabufPlanes& planes, Imported& imported);
  void destroy(Imported& imported);
  // Destroys and forgets the imports `drop` picks.
  template <typename Drop>
  void forget(Drop drop);

  PixelFormat format_;
  cv::Size size_;
  EGLDisplay display_;
  PFNEGLCREATEIMAGEKHRPROC createImage_ = nullptr;
  PFNEGLDESTROYIMAGEKHRPROC destroyImage_ = nullptr;
  void (*targetTexture_)(GLenum, void*) = nullptr;  // glEGLImageTargetTexture2DOES
  std::vector<Imported> kept_;                      // oldest first
  std::uint64_t session_ = 0;                       // the latest streaming session seen
  std::string refusal_;
};

}  // namespace surroundd::render
