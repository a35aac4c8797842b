#include "render/gpu_stitcher.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "common/work_pool.hpp"
#include "render/render_error.hpp"

namespace surroundd::render {
namespace {

using processing::LutTap;
using processing::PanoramaLut;

constexpr const char* kVertex = R"(#version 300 es
void main() {
  gl_Position = vec4(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0, 0.0, 1.0);
})";

// The parts of the fragment shader that do not depend on the rig. A tap's second word is
// fx | fy << 8 | camera << 16 | weight << 24 (LutTap's bytes in order, little-endian as the
// upload left them). Colours are levels 0..255 in the frame's channel order until the end.
constexpr const char* kFragmentHead = R"(#version 300 es
precision highp float;
precision highp int;
precision highp usampler2D;
uniform usampler2D u_taps;
uniform usampler2D u_blends;
uniform int u_correction;   // 0 none, 1 multiplicative, 2 additive
uniform int u_block;        // the correction's block side, pixels
uniform sampler2D u_field;  // its field on the block grid, levels at 255 (texelFetch only)
uniform usampler2D u_shares;
uniform int u_balanced;     // 1: each camera's gains (u_gains) before the field
out vec4 o_colour;

// cv::cvtColor's BT.601 limited-range constants (its 20-bit fixed point, as yuvToBgr() in
// common/pixel_format.hpp), to B G R levels.
vec3 toBgr(vec3 yuv) {
  float luma = max(yuv.x - 16.0, 0.0) * (1220542.0 / 1048576.0);
  float cb = yuv.y - 128.0;
  float cr = yuv.z - 128.0;
  return clamp(vec3(luma + (2116026.0 / 1048576.0) * cb,
                    luma - (409993.0 / 1048576.0) * cb - (852492.0 / 1048576.0) * cr,
                    luma + (1673527.0 / 1048576.0) * cr), 0.0, 255.0);
}

// PoissonColourCorrection::apply() in processing/colour/poisson_correction.cpp: its Catmull-Rom
// weights, the taps of a pixel's sub-block phase (columns wrap around, rows are clamped), and
// its rule for a pixel's level given the source cameras' share of it.
vec4 catmullRom(float t) {
  float t2 = t * t;
  float t3 = t2 * t;
  return vec4(-t3 + 2.0 * t2 - t, 3.0 * t3 - 5.0 * t2 + 2.0, -3.0 * t3 + 4.0 * t2 + t, t3 - t2) *
         0.5;
}
vec3 fieldAt(ivec2 pixel) {
  ivec2 grid = textureSize(u_field, 0);
  vec2 t = (vec2(pixel % u_block) + 0.5) / float(u_block) - 0.5;
  vec2 below = floor(t);
  ivec2 first = pixel / u_block + ivec2(below) - 1;
  vec4 wx = catmullRom(t.x - below.x);
  vec4 wy = catmullRom(t.y - below.y);
  vec3 sum = vec3(0.0);
  for (int j = 0; j < 4; ++j) {
    int row = clamp(first.y + j, 0, grid.y - 1);
    vec3 across = vec3(0.0);
    for (int i = 0; i < 4; ++i) {
      int column = (first.x + i + grid.x) % grid.x;
      across += wx[i] * texelFetch(u_field, ivec2(column, row), 0).rgb;
    }
    sum += wy[j] * across;
  }
  return sum;
}
vec3 corrected(vec3 level, ivec2 pixel) {
  uint share = texelFetch(u_shares, pixel, 0).r;
  if (share == 0u) return level;
  vec3 value = fieldAt(pixel);
  float weight = float(share) / 256.0;
  level = floor(level + 0.5);  // the stitched panorama's 8-bit levels, which apply() corrects
  if (u_correction == 2) return clamp(level + weight * value, 0.0, 255.0);
  vec3 gain = 1.0 + value / 255.0;
  // In the seam band the pixel is w * source + (1 - w) * target: only the source's part scales.
  return clamp(share == 256u ? level * gain : level * gain / (weight + (1.0 - weight) * gain),
               0.0, 255.0);
}
)";

// One camera's texel at a pixel, in the frame's format: `{0}` is the camera's index.
std::string texelFunction(PixelFormat format, std::size_t camera) {
  switch (format) {
    case PixelFormat::kBgr:
      return fmt::format(R"(uniform sampler2D u_pixels{0};
vec3 texel{0}(ivec2 p) {{ return texelFetch(u_pixels{0}, p, 0).rgb * 255.0; }}
)",
                         camera);
    case PixelFormat::kYuyv:
    case PixelFormat::kUyvy:
      // Each texel is a pair, Y0 Cb Y1 Cr (YUYV) or Cb Y0 Cr Y1 (UYVY), swizzled to Y0 Y1 Cb Cr:
      // a pixel takes its pair's chroma, as cvtColor does.
      return fmt::format(R"(uniform sampler2D u_pixels{0};
vec3 texel{0}(ivec2 p) {{
  vec4 pair = texelFetch(u_pixels{0}, ivec2(p.x >> 1, p.y), 0).{1} * 255.0;
  return vec3((p.x & 1) == 0 ? pair.x : pair.y, pair.z, pair.w);
}}
)",
                         camera, format == PixelFormat::kYuyv ? "rbga" : "garb");
    case PixelFormat::kNv12:
      return fmt::format(R"(uniform sampler2D u_pixels{0};
uniform sampler2D u_chroma{0};
vec3 texel{0}(ivec2 p) {{
  return vec3(texelFetch(u_pixels{0}, p, 0).r, texelFetch(u_chroma{0}, p >> 1, 0).rg) * 255.0;
}}
)",
                         camera);
  }
  return {};
}

// Camera `camera`'s bilinear sample at a tap (its pixel offset and fractions), in B G R levels.
std::string sampleFunction(PixelFormat format, std::size_t camera, int width) {
  return fmt::format(R"(vec3 sample{0}(uint offset, vec2 fraction) {{
  ivec2 p = ivec2(int(offset % {1}u), int(offset / {1}u));
  vec3 top = mix(texel{0}(p), texel{0}(p + ivec2(1, 0)), fraction.x);
  vec3 bottom = mix(texel{0}(p + ivec2(0, 1)), texel{0}(p + ivec2(1, 1)), fraction.x);
  return {2}(mix(top, bottom, fraction.y));
}}
)",
                     camera, width, format == PixelFormat::kBgr ? "" : "toBgr");
}

std::string fragmentSource(const PanoramaLut& lut, PixelFormat format) {
  std::string source = kFragmentHead;
  std::string dispatch;
  for (std::size_t camera = 0; camera < lut.cameraSizes.size(); ++camera) {
    source += texelFunction(format, camera);
    source += sampleFunction(format, camera, lut.cameraSizes[camera].width);
    // GLSL ES 3.00 indexes sampler arrays only with constants: one branch per camera instead.
    dispatch += fmt::format("  if (camera == {0}u) return sample{0}(tap.x, fraction);\n", camera);
  }
  const cv::Vec3b unseen = PanoramaLut::kUnseenColour;
  source += fmt::format(R"(vec3 sampleTap(uvec2 tap) {{
  uint camera = (tap.y >> 16) & 255u;
  vec2 fraction = vec2(float(tap.y & 255u), float((tap.y >> 8) & 255u)) / {0}.0;
{1}  return vec3({2}.0, {3}.0, {4}.0);
}}
// applyCameraGains() in processing/colour/camera_gains.cpp: the pixel's camera's gains, in a seam
// band their harmonic mix with the other camera's, on the stitched panorama's 8-bit levels.
uniform vec3 u_gains[{5}];
vec3 balanced(vec3 level, uvec2 tap, uvec2 blend, uint weight) {{
  uint camera = (tap.y >> 16) & 255u;
  if (camera == {6}u) return level;
  vec3 gain = u_gains[camera];
  uint other = (blend.y >> 16) & 255u;
  if (weight != 0u && other != {6}u) {{
    gain = 1.0 / mix(1.0 / gain, 1.0 / u_gains[other], float(weight) / 256.0);
  }}
  return clamp(floor(floor(level + 0.5) * gain + 0.5), 0.0, 255.0);
}}
void main() {{
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  uvec2 tap = texelFetch(u_taps, pixel, 0).xy;
  vec3 colour = sampleTap(tap);
  uvec2 blend = texelFetch(u_blends, pixel, 0).xy;
  uint weight = blend.y >> 24;
  if (weight != 0u) colour = mix(colour, sampleTap(blend), float(weight) / 256.0);
  if (u_balanced != 0) colour = balanced(colour, tap, blend, weight);
  if (u_correction != 0) colour = corrected(colour, pixel);
  o_colour = vec4(colour.bgr / 255.0, 1.0);
}}
)",
                        LutTap::kFractionOne, dispatch, unseen[0], unseen[1], unseen[2],
                        lut.cameraSizes.size(), static_cast<int>(PanoramaLut::kUnseen));
  return source;
}

// Taps as an RG32UI texture of the panorama's size.
void uploadTaps(GLuint texture, cv::Size size, const LutTap* taps) {
  static_assert(sizeof(LutTap) == 2 * sizeof(std::uint32_t));
  glBindTexture(GL_TEXTURE_2D, texture);
  glTexStorage2D(GL_TEXTURE_2D, 1, GL_RG32UI, size.width, size.height);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, size.width, size.height, GL_RG_INTEGER, GL_UNSIGNED_INT,
                  taps);
}

}  // namespace

GpuStitcher::GpuStitcher(const PanoramaLut& lut, PixelFormat format, WorkPool& pool)
    : size_(lut.size),
      format_(format),
      pool_(pool),
      program_(fmt::format("GPU stitch ({})", toString(format)), kVertex,
               fragmentSource(lut, format)),
      correctionUniform_(program_.uniform("u_correction")),
      blockUniform_(program_.uniform("u_block")),
      balancedUniform_(program_.uniform("u_balanced")),
      gainsUniform_(program_.uniform("u_gains")) {
  GLint maxSize = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxSize);
  if (size_.width > maxSize || size_.height > maxSize) {
    throw RenderError(fmt::format("a {}x{} panorama exceeds this GPU's textures ({} pixels)",
                                  size_.width, size_.height, maxSize));
  }
  cameras_.reserve(lut.cameraSizes.size());
  for (const cv::Size& cameraSize : lut.cameraSizes) cameras_.emplace_back(format, cameraSize);
  mapped_.resize(cameras_.size());
  imported_.resize(cameras_.size());

  uploadTaps(taps_.name(), size_, lut.taps.data());
  // The blend taps spread out to one per pixel (weight 0: none), so that the shader finds a
  // pixel's own without a search. Set-up only.
  std::vector<LutTap> blends(lut.taps.size());
  for (const auto& blend : lut.blendTaps) blends[blend.pixel] = blend.tap;
  uploadTaps(blends_.name(), size_, blends.data());

  glBindTexture(GL_TEXTURE_2D, panorama_.name());
  glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, size_.width, size_.height);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);  // azimuth wraps around
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.name());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, panorama_.name(), 0);
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw RenderError(
        fmt::format("the GPU panorama's framebuffer is incomplete (0x{:04x})", status));
  }

  // Texture units: 0 taps, 1 blends, 2 the correction's field, 3 its shares, then each camera's
  // pixels (and chroma) in turn.
  glUseProgram(program_.name());
  glUniform1i(program_.uniform("u_taps"), 0);
  glUniform1i(program_.uniform("u_blends"), 1);
  glUniform1i(program_.uniform("u_field"), 2);
  glUniform1i(program_.uniform("u_shares"), 3);
  glUniform1i(correctionUniform_, 0);
  glUniform1i(balancedUniform_, 0);
  GLint unit = 4;
  for (std::size_t camera = 0; camera < cameras_.size(); ++camera) {
    glUniform1i(program_.uniform(fmt::format("u_pixels{}", camera).c_str()), unit++);
    if (format == PixelFormat::kNv12) {
      glUniform1i(program_.uniform(fmt::format("u_chroma{}", camera).c_str()), unit++);
    }
  }
  GLint maxUnits = 0;
  glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &maxUnits);
  if (unit > maxUnits) {
    throw RenderError(
        fmt::format("the GPU stitch of {} cameras needs {} texture units, this GPU "
                    "has {}",
                    cameras_.size(), unit, maxUnits));
  }
  gl::check("setting up the GPU stitch");
}

void GpuStitcher::upload(std::span<const cv::Mat> frames, std::span<const DmabufPlanes> dmabufs) {
  if (frames.size() != cameras_.size() || (!dmabufs.empty() && dmabufs.size() != frames.size())) {
    throw std::invalid_argument(fmt::format("the GPU stitch takes {} frames, got {} ({} DMABUFs)",
                                            cameras_.size(), frames.size(), dmabufs.size()));
  }
  // Every frame checked before any buffer is mapped: a buffer left mapped would fail every later
  // upload.
  for (std::size_t camera = 0; camera < frames.size(); ++camera) {
    cameras_[camera].check(frames[camera]);
  }
  for (std::size_t camera = 0; camera < frames.size(); ++camera) {
    const bool inDmabuf = !dmabufs.empty() && dmabufs[camera].planes > 0;
    imported_[camera] = static_cast<char>(inDmabuf && cameras_[camera].import(dmabufs[camera]));
    mapped_[camera] = {};
    try {
      if (imported_[camera] == 0) mapped_[camera] = cameras_[camera].map();
    } catch (...) {
      for (std::size_t earlier = 0; earlier < camera; ++earlier) {
        if (!mapped_[earlier].empty()) cameras_[earlier].unmap();
      }
      throw;
    }
  }
  // Each camera's bytes in a few pieces, so that every thread has a share whatever the count.
  constexpr int kPieces = 4;
  const auto cameras = static_cast<int>(frames.size());
  pool_.parallelFor(cameras * kPieces, [&](int begin, int end) {
    for (int piece = begin; piece < end; ++piece) {
      const auto camera = static_cast<std::size_t>(piece / kPieces);
      const std::span<std::uint8_t> buffer = mapped_[camera];
      const std::size_t first = buffer.size() * (piece % kPieces) / kPieces;
      const std::size_t last = buffer.size() * (piece % kPieces + 1) / kPieces;
      if (last > first)
        std::memcpy(buffer.data() + first, frames[camera].data + first, last - first);
    }
  });
  for (std::size_t camera = 0; camera < frames.size(); ++camera) {
    if (imported_[camera] == 0) cameras_[camera].commit();
  }
}

void GpuStitcher::correctWith(const std::optional<processing::ColourField>& field) {
  if (field && field->shares.size() != static_cast<std::size_t>(size_.area())) {
    throw std::invalid_argument("the correction was set up for another panorama");
  }
  if (field && !field->cameraGains.empty() && field->cameraGains.size() != cameras_.size()) {
    throw std::invalid_argument(fmt::format("the correction has gains for {} cameras, not {}",
                                            field->cameraGains.size(), cameras_.size()));
  }
  fieldValues_ = field ? field->values : nullptr;
  cameraGains_ = field ? field->cameraGains : std::span<const cv::Vec3f>();
  glUseProgram(program_.name());
  glUniform1i(balancedUniform_, cameraGains_.empty() ? 0 : 1);
  if (!field) {
    glUniform1i(correctionUniform_, 0);
    return;
  }
  const cv::Size grid = field->values->size();
  field_ = gl::Texture();
  glBindTexture(GL_TEXTURE_2D, field_.name());
  glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGB32F, grid.width, grid.height);
  shares_ = gl::Texture();
  glBindTexture(GL_TEXTURE_2D, shares_.name());
  glTexStorage2D(GL_TEXTURE_2D, 1, GL_R16UI, size_.width, size_.height);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 2);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, size_.width, size_.height, GL_RED_INTEGER,
                  GL_UNSIGNED_SHORT, field->shares.data());
  for (const GLuint texture : {field_.name(), shares_.name()}) {
    glBindTexture(GL_TEXTURE_2D, texture);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }
  glUniform1i(correctionUniform_, field->additive ? 2 : 1);
  glUniform1i(blockUniform_, field->block);
  gl::check("setting up the GPU colour correction");
}

void GpuStitcher::stitch() {
  if (fieldValues_ != nullptr) {
    // The field as the last update() left it: a few thousand blocks, uploaded as they are.
    const cv::Mat& field = *fieldValues_;
    glBindTexture(GL_TEXTURE_2D, field_.name());
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, field.cols, field.rows, GL_RGB, GL_FLOAT, field.data);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.name());
  glViewport(0, 0, size_.width, size_.height);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(program_.name());
  if (!cameraGains_.empty()) {
    // As the last update() left them.
    static_assert(sizeof(cv::Vec3f) == 3 * sizeof(float));
    glUniform3fv(gainsUniform_, static_cast<GLsizei>(cameraGains_.size()),
                 cameraGains_.front().val);
  }
  const auto bind = [](GLint unit, GLuint texture) {
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(GL_TEXTURE_2D, texture);
  };
  bind(0, taps_.name());
  bind(1, blends_.name());
  bind(2, field_.name());
  bind(3, shares_.name());
  GLint unit = 4;
  for (const auto& camera : cameras_) {
    bind(unit++, camera.pixels());
    if (format_ == PixelFormat::kNv12) bind(unit++, camera.chroma());
  }
  glBindVertexArray(emptyArray_.name());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glActiveTexture(GL_TEXTURE0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (std::ranges::any_of(imported_, [](char imported) { return imported != 0; })) {
    GLsync read = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    constexpr GLuint64 kSecond = 1'000'000'000;
    const GLenum waited = glClientWaitSync(read, GL_SYNC_FLUSH_COMMANDS_BIT, kSecond);
    glDeleteSync(read);
    if (waited == GL_TIMEOUT_EXPIRED || waited == GL_WAIT_FAILED) {
      glFinish();  // the set's end gives the frames' buffers back to their driver
      throw RenderError("the GPU stitch of imported frames did not finish within a second");
    }
  }
  gl::check("stitching on the GPU");
}

void GpuStitcher::readPanorama(cv::Mat& bgr) const {
  cv::Mat rgba(size_, CV_8UC4);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.name());
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, size_.width, size_.height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  gl::check("reading the GPU panorama back");
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
}

}  // namespace surroundd::render
