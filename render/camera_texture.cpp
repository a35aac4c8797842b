#include "render/camera_texture.hpp"

#include <cstring>
#include <stdexcept>

#include <fmt/core.h>

#include "render/render_error.hpp"

namespace surroundd::render {
namespace {

// One level, no filtering: the stitch shader reads exact texels and interpolates itself (YUV
// must be interpolated before it is converted, and packed YUYV cannot be filtered by the
// hardware at all).
void allocate(GLuint texture, GLenum internalFormat, cv::Size size) {
  glBindTexture(GL_TEXTURE_2D, texture);
  glTexStorage2D(GL_TEXTURE_2D, 1, internalFormat, size.width, size.height);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

// With a pixel unpack buffer bound, GL takes the offset into it in the pointer argument.
const void* bufferOffset(std::size_t offset) {
  return reinterpret_cast<const void*>(offset);  // NOLINT(performance-no-int-to-ptr)
}

}  // namespace

CameraTexture::CameraTexture(PixelFormat format, cv::Size size)
    : format_(format),
      size_(size),
      bytes_(static_cast<std::size_t>(heldSize(format, size).area()) *
             CV_ELEM_SIZE(heldType(format))) {
  if (format != PixelFormat::kBgr && (size.width % 2 != 0 || size.height % 2 != 0)) {
    throw std::invalid_argument(fmt::format("a {} camera texture needs an even size, not {}x{}",
                                            toString(format), size.width, size.height));
  }
  switch (format_) {
    case PixelFormat::kBgr:
      allocate(pixels_.name(), GL_RGB8, size);
      break;
    case PixelFormat::kYuyv:
    case PixelFormat::kUyvy:
      allocate(pixels_.name(), GL_RGBA8, {size.width / 2, size.height});
      break;
    case PixelFormat::kNv12:
      allocate(pixels_.name(), GL_R8, size);
      allocate(chroma_.name(), GL_RG8, {size.width / 2, size.height / 2});
      break;
  }
  for (const auto& buffer : buffers_) {
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, buffer.name());
    glBufferData(GL_PIXEL_UNPACK_BUFFER, static_cast<GLsizeiptr>(bytes_), nullptr, GL_STREAM_DRAW);
  }
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  gl::check(fmt::format("creating a {} camera texture", toString(format)).c_str());
  shown_ = {pixels_.name(), format_ == PixelFormat::kNv12 ? chroma_.name() : 0};
}

bool CameraTexture::import(const DmabufPlanes& planes) {
  if (!import_) import_ = std::make_unique<DmabufImport>(format_, size_);
  const auto textures = import_->texturesOf(planes);
  if (textures) shown_ = *textures;
  return textures.has_value();
}

const std::string& CameraTexture::importRefusal() const {
  static const std::string kNone;
  return import_ ? import_->refusal() : kNone;
}

void CameraTexture::upload(const cv::Mat& held) {
  check(held);
  std::memcpy(map().data(), held.data, bytes_);
  commit();
}

void CameraTexture::check(const cv::Mat& held) const {
  if (!holds(held, format_, size_)) {
    throw std::invalid_argument(fmt::format("a camera texture of {} {}x{} got a frame of {}x{}",
                                            toString(format_), size_.width, size_.height, held.cols,
                                            held.rows));
  }
}

std::span<std::uint8_t> CameraTexture::map() {
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, buffers_[next_].name());
  void* mapped = glMapBufferRange(GL_PIXEL_UNPACK_BUFFER, 0, static_cast<GLsizeiptr>(bytes_),
                                  GL_MAP_WRITE_BIT | GL_MAP_INVALIDATE_BUFFER_BIT);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  if (mapped == nullptr) {
    gl::check("mapping a camera upload buffer");
    throw RenderError("mapping a camera upload buffer failed");
  }
  return {static_cast<std::uint8_t*>(mapped), bytes_};
}

void CameraTexture::unmap() {
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, buffers_[next_].name());
  glUnmapBuffer(GL_PIXEL_UNPACK_BUFFER);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
}

void CameraTexture::commit() {
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, buffers_[next_].name());
  next_ = (next_ + 1) % buffers_.size();
  glUnmapBuffer(GL_PIXEL_UNPACK_BUFFER);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glBindTexture(GL_TEXTURE_2D, pixels_.name());
  switch (format_) {
    case PixelFormat::kBgr:
      glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, size_.width, size_.height, GL_RGB, GL_UNSIGNED_BYTE,
                      bufferOffset(0));
      break;
    case PixelFormat::kYuyv:
    case PixelFormat::kUyvy:
      glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, size_.width / 2, size_.height, GL_RGBA,
                      GL_UNSIGNED_BYTE, bufferOffset(0));
      break;
    case PixelFormat::kNv12:
      glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, size_.width, size_.height, GL_RED, GL_UNSIGNED_BYTE,
                      bufferOffset(0));
      glBindTexture(GL_TEXTURE_2D, chroma_.name());
      glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, size_.width / 2, size_.height / 2, GL_RG,
                      GL_UNSIGNED_BYTE, bufferOffset(static_cast<std::size_t>(size_.area())));
      break;
  }
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  gl::check("uploading a camera frame");
  shown_ = {pixels_.name(), format_ == PixelFormat::kNv12 ? chroma_.name() : 0};
}

}  // namespace surroundd::render
