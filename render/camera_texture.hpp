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

#include <array>
#include <cstdint>
#include <span>

#include <opencv2/core.hpp>

#include "common/pixel_format.hpp"
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

  PixelFormat format() const { return format_; }
  cv::Size size() const { return size_; }
  // YUYV and BGR: the one texture; NV12: the luma.
  GLuint pixels() const { return pixels_.name(); }
  // NV12: the chroma texture; 0 for the others.
  GLuint chroma() const { return format_ == PixelFormat::kNv12 ? chroma_.name() : 0; }

 private:
  PixelFormat format_;
  cv::Size size_;
  std::size_t bytes_;
  gl::Texture pixels_;
  gl::Texture chroma_;
  std::array<gl::Buffer, 2> buffers_;
  std::size_t next_ = 0;
};

}  // namespace surroundd::render
