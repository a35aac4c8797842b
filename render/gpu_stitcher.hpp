#pragma once
// The panorama stitched on the GPU: the same PanoramaLut the CPU Stitcher applies, kept in
// textures, sampled from the camera frames as they were held (YUYV, NV12 or BGR, converted in the
// shader) by one full-screen pass into a panorama texture that the surround scene samples in
// place (SurroundScene::samplePanoramaFrom): no panorama on the CPU, no upload of it.
//
// The shader does what Stitcher does (processing/stitch/stitcher.hpp): each pixel's tap is a 2x2
// neighbourhood interpolated bilinearly in the frame's own format and converted to colour with
// cv::cvtColor's BT.601 constants, its blend tap mixed in by its weight, the unseen colour where
// no camera sees; in floating point rather than in Stitcher's fixed point, so the two agree
// within rounding (tested: gpu_stitcher_test). With a colour correction it applies its field
// (processing/colour_field.hpp) in the same pass as PoissonColourCorrection::apply() does (the
// block grid upsampled with the same Catmull-Rom weights, the same multiplicative or additive rule
// and seam-band shares): the correction's solve stays on the CPU, and only its small field is
// uploaded per frame.
//
// Built at start-up on the thread of the current EglContext; upload() and stitch() are the
// per-frame calls and allocate nothing.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "common/dmabuf_planes.hpp"
#include "common/pixel_format.hpp"
#include "processing/colour_field.hpp"
#include "processing/stitch/panorama_lut.hpp"
#include "render/camera_texture.hpp"
#include "render/gl_objects.hpp"
#include "render/shader_program.hpp"

namespace surroundd {
class WorkPool;
}

namespace surroundd::render {

class GpuStitcher {
 public:
  // Frames of every camera arrive in `format`. Throws RenderError when the driver lacks what it
  // needs (a texture of the LUT's size, the program). Borrows the pool, which copies the frames
  // into the pixel buffers: it must outlive the stitcher.
  GpuStitcher(const processing::PanoramaLut& lut, PixelFormat format, WorkPool& pool);

  // frames[i]: camera i's frame held in format(), of the LUT's size for that camera; throws
  // std::invalid_argument otherwise. The copies into the mapped pixel buffers run on the pool
  // (one memcpy per thread cannot keep up with the bus: 12 GB/s where PCIe carries 25 or more).
  // dmabufs[i], where given, says where camera i's frame lies in DMABUFs: it is imported instead
  // (CameraTexture::import), and uploaded where it cannot be (imported() and importRefusal() say
  // which way each camera's went). Until stitch() has run, the DMABUFs must stay as they are.
  void upload(std::span<const cv::Mat> frames, std::span<const DmabufPlanes> dmabufs = {});
  // Whether camera i's last frame was imported rather than uploaded.
  bool imported(std::size_t camera) const { return imported_[camera]; }
  // Why camera i's frames are not imported (empty until the first import is tried, and while
  // they are).
  const std::string& importRefusal(std::size_t camera) const {
    return cameras_[camera].importRefusal();
  }
  // Applies `field` from the next stitch() on, its values as they stand at each stitch (borrowed:
  // its correction must outlive its use here); none: no correction. Set-up, not per frame: it
  // uploads the field's shares (two bytes a panorama pixel).
  void correctWith(const std::optional<processing::ColourField>& field);
  // Writes the panorama texture from the frames last uploaded (and the correction's field as it
  // is now), and waits for the GPU to have read any imported frame: their buffers go back to the
  // camera's driver once the set is done. Leaves framebuffer 0 bound and texture unit 0 active.
  void stitch();

  // RGBA8, the LUT's size, row 0 the panorama's top at texture coordinate t = 0, repeated
  // across azimuth and linearly filtered: what the surround mesh samples.
  GLuint panorama() const { return panorama_.name(); }
  cv::Size size() const { return size_; }
  PixelFormat format() const { return format_; }

  // The panorama as 8-bit BGR, waiting for the GPU (tests and measurements, not the per-frame
  // path: read-back for outputs is SurroundView's).
  void readPanorama(cv::Mat& bgr) const;

 private:
  cv::Size size_;
  PixelFormat format_;
  WorkPool& pool_;
  std::vector<CameraTexture> cameras_;
  std::vector<std::span<std::uint8_t>> mapped_;  // each camera's buffer while an upload fills it
  std::vector<char> imported_;                   // per camera: its last frame imported
  gl::Texture taps_;                             // RG32UI: each pixel's LutTap as two words
  gl::Texture blends_;                    // the same for its blend tap; weight 0 where it has none
  const cv::Mat* fieldValues_ = nullptr;  // the correction's block grid, null with none
  std::span<const cv::Vec3f> cameraGains_;  // the correction's, before its field; empty: none
  gl::Texture field_;                       // RGB32F, its copy uploaded per stitch
  gl::Texture shares_;                      // R16UI, each panorama pixel's source share 0..256
  gl::Texture panorama_;
  gl::Framebuffer framebuffer_;
  gl::VertexArray emptyArray_;  // the full-screen triangle makes its vertices from gl_VertexID
  ShaderProgram program_;
  GLint correctionUniform_;  // 0 none, 1 multiplicative, 2 additive
  GLint blockUniform_;
  GLint balancedUniform_;
  GLint gainsUniform_;
};

}  // namespace surroundd::render
