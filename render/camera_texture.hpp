#pragma once
// One camera's frames on the GPU, in the format the camera held them (common/pixel_format.hpp):
// uploaded as they are and converted by the shader that samples them, so the CPU never touches a
// pixel. YUYV and UYVY are one RGBA8 texture of half the width (a texel is Y0 Cb Y1 Cr, or
// Cb Y0 Cr Y1); NV12 is an R8 luma
// texture and an RG8 chroma texture of half the width and height; BGR is one RGB8 texture (red
// holding blue: the sampling shader knows). Every texture is sampled with texelFetch.
//
// Uploads stream through two pixel buffer objects in turn: the CPU fills one while the GPU may
// still be reading the other, so neither waits for the other. The filling may run on any thread
// (map() and commit() on the GL thread, the copy in between anywhere), so that a caller can copy
// several cameras' frames at once.
//
// A frame that lies in a DMABUF may be imported instead (render/dmabuf_import.hpp): no copy at
// all. The textures sampled are then the import's, until the next upload.

#include <array>
#include <cstdint>
#include <memory>
#include <span>

#include <opencv2/core.hpp>

#include "common/dmabuf_planes.hpp"
#include "common/pixel_format.hpp"
#include "render/dmabuf_import.hpp"
#include "render/gl_objects.hpp"

namespace surroundd::render {

class CameraTexture {
 public:
  // On the thread of the current EglContext. `size`: the picture's size (even for YUV).
  CameraTexture(PixelFormat format, cv::Size size);

  // `held` must hold a picture of this size in this format (holds()); throws
  // std::invalid_argument otherwise, RenderError when the driver fails.
  void upload(const cv::Mat& held);
  // upload() in three steps: check the frame (as upload() does), map the next pixel buffer for
  // the frame's bytes, then, once they are in it, commit() it to the textures.
  void check(const cv::Mat& held) const;
  std::span<std::uint8_t> map();
  void commit();
  // Gives a mapped buffer back unfilled: the textures keep the last frame.
  void unmap();
  // Takes the frame from the DMABUF it lies in instead: true when it did; false, and nothing
  // changed, when it cannot (importRefusal() says why; the import is not tried again).
  bool import(const DmabufPlanes& planes);
  // Why frames are not imported (empty before the first import() and while they are).
  const std::string& importRefusal() const;

  PixelFormat format() const { return format_; }
  cv::Size size() const { return size_; }
  // The frame last uploaded or imported. YUYV and BGR: the one texture; NV12: the luma.
  GLuint pixels() const { return shown_[0]; }
  // NV12: the chroma texture; 0 for the others.
  GLuint chroma() const { return shown_[1]; }

 private:
  PixelFormat format_;
  cv::Size size_;
  std::size_t bytes_;
  gl::Texture pixels_;
  gl::Texture chroma_;
  std::array<gl::Buffer, 2> buffers_;
  std::size_t next_ = 0;
  std::array<GLuint, 2> shown_{};         // the textures holding the last frame
  std::unique_ptr<DmabufImport> import_;  // from the first import() on
};

}  // namespace surroundd::render
