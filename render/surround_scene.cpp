#include "render/surround_scene.hpp"

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

namespace surroundd::render {
namespace {

constexpr const char* kMeshVertex = R"(#version 300 es
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec2 a_uv;
uniform mat4 u_viewProjection;
out vec2 v_uv;
void main() {
  v_uv = a_uv;
  gl_Position = u_viewProjection * vec4(a_position, 1.0);
})";

constexpr const char* kMeshFragment = R"(#version 300 es
precision highp float;
uniform sampler2D u_panorama;
in vec2 v_uv;
out vec4 o_colour;
void main() {
#ifdef PANORAMA_POSITIONS
  o_colour = panoramaPosition(v_uv);
#else
  o_colour = vec4(texture(u_panorama, v_uv).rgb, 1.0);
#endif
})";

constexpr const char* kCarVertex = R"(#version 300 es
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_colour;
layout(location = 3) in vec2 a_uv;
uniform mat4 u_viewProjection;
out vec3 v_colour;
out vec2 v_uv;
void main() {
  v_uv = a_uv;
  // One light from above, a little ahead and to the left, and some ambient.
  float lambert = max(dot(a_normal, normalize(vec3(0.3, 0.4, 1.0))), 0.0);
  v_colour = a_colour * (0.35 + 0.65 * lambert);
  gl_Position = u_viewProjection * vec4(a_position, 1.0);
})";

constexpr const char* kCarFragment = R"(#version 300 es
precision mediump float;
uniform sampler2D u_texture;  // the part's, or one white texel
in vec3 v_colour;
in vec2 v_uv;
out vec4 o_colour;
void main() {
#ifdef PANORAMA_POSITIONS
  o_colour = vec4(0.0);
#else
  o_colour = vec4(v_colour * texture(u_texture, v_uv).rgb, 1.0);
#endif
})";

// The guidelines: flat colours on the ground, unlit, so that they read the same in every view.
constexpr const char* kGuidelineVertex = R"(#version 300 es
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_colour;
uniform mat4 u_viewProjection;
out vec3 v_colour;
void main() {
  v_colour = a_colour;
  gl_Position = u_viewProjection * vec4(a_position, 1.0);
})";

constexpr const char* kGuidelineFragment = R"(#version 300 es
precision mediump float;
in vec3 v_colour;
out vec4 o_colour;
void main() { o_colour = vec4(v_colour, 1.0); })";

// One triangle covering the viewport. v_picture: x -1 (left) .. 1 (right), y -1 (bottom) .. 1
// (top) of the picture; framebuffer row 0 is the top (see view_camera.hpp).
constexpr const char* kFullViewportVertex = R"(#version 300 es
out vec2 v_picture;
void main() {
  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  v_picture = vec2(p.x, -p.y);
  gl_Position = vec4(p, 0.0, 1.0);
})";

constexpr const char* kStripFragment = R"(#version 300 es
precision highp float;
uniform sampler2D u_panorama;
uniform vec2 u_tangents;      // tan(elevation) at the top and bottom of a strip
uniform float u_panoramaTop;  // the panorama's elevation range, radians
uniform float u_panoramaSpan;
in vec2 v_picture;
out vec4 o_colour;
const float PI = 3.14159265358979;
void main() {
  bool front = v_picture.y >= 0.0;
  float across = (v_picture.x + 1.0) * 0.5;
  // Front strip: left (+90 deg) to right (-90); back strip: right (-90) through the back to left.
  float azimuth = front ? PI * (0.5 - across) : -PI * (0.5 + across);
  float up = front ? v_picture.y : v_picture.y + 1.0;  // 0 at the bottom of a strip, 1 at its top
  float elevation = atan(mix(u_tangents.y, u_tangents.x, up));
  vec2 uv = vec2(fract((azimuth + PI) / (2.0 * PI)), (u_panoramaTop - elevation) / u_panoramaSpan);
  bool outside = uv.y < 0.0 || uv.y > 1.0;
#ifdef PANORAMA_POSITIONS
  o_colour = outside ? vec4(0.0) : panoramaPosition(uv);
#else
  o_colour = outside ? vec4(0.0, 0.0, 0.0, 1.0) : vec4(texture(u_panorama, uv).rgb, 1.0);
#endif
})";

constexpr const char* kPictureFragment = R"(#version 300 es
precision mediump float;
uniform sampler2D u_picture;
in vec2 v_picture;
out vec4 o_colour;
void main() {
  o_colour = vec4(texture(u_picture, vec2(v_picture.x + 1.0, 1.0 - v_picture.y) * 0.5).rgb, 1.0);
})";

// Where a fragment samples the panorama (texture coordinates), packed into an 8-bit RGBA target
// (read back fast where a float one is slow, and drawn where float targets are missing): u in 16
// bits (red, green; it wraps), v in 15 (blue's low 7, alpha), blue's top bit set where the panorama
// is shown. SurroundView::panoramaPositions() unpacks it.
constexpr const char* kPackPanoramaPosition = R"(
highp vec4 panoramaPosition(highp vec2 uv) {
  highp float u = mod(floor(fract(uv.x) * 65536.0 + 0.5), 65536.0);
  highp float v = floor(clamp(uv.y, 0.0, 1.0) * 32767.0 + 0.5);
  return vec4(floor(u / 256.0), mod(u, 256.0), 128.0 + floor(v / 256.0), mod(v, 256.0)) / 255.0;
}
)";

// A fragment shader's source with PANORAMA_POSITIONS defined and panoramaPosition() (after its
// #version line, which must come first).
std::string withPanoramaPositions(std::string_view fragment) {
  const std::size_t body = fragment.find('\n') + 1;
  return fmt::format("{}#define PANORAMA_POSITIONS\n{}{}", fragment.substr(0, body),
                     kPackPanoramaPosition, fragment.substr(body));
}

void attribute(GLuint index, GLint components, GLsizei stride, std::size_t offset) {
  glEnableVertexAttribArray(index);
  // With a vertex buffer bound, GL takes the offset into it in the pointer argument.
  glVertexAttribPointer(
      index, components, GL_FLOAT, GL_FALSE, stride,
      reinterpret_cast<const void*>(offset));  // NOLINT(performance-no-int-to-ptr)
}

void requireBgr(const cv::Mat& image, cv::Size size, const char* what) {
  if (image.type() != CV_8UC3 || image.size() != size) {
    throw std::invalid_argument(fmt::format("{}: expected 8-bit BGR {}x{}, got {}x{} of type {}",
                                            what, size.width, size.height, image.cols, image.rows,
                                            image.type()));
  }
}

// A texture of the car model: 8-bit RGBA, repeated as glTF's default sampler does, mipmapped as the
// car is often seen small.
gl::Texture carTexture(const cv::Mat& rgba) {
  gl::Texture texture;
  glBindTexture(GL_TEXTURE_2D, texture.name());
  const cv::Mat rows = rgba.isContinuous() ? rgba : rgba.clone();
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, rows.cols, rows.rows, 0, GL_RGBA, GL_UNSIGNED_BYTE,
               rows.data);
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  gl::check("uploading a car model texture");
  return texture;
}

}  // namespace

SurroundScene::StreamedTexture::StreamedTexture(cv::Size textureSize, GLint horizontalWrap)
    : size(textureSize) {
  glBindTexture(GL_TEXTURE_2D, texture.name());
  glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, size.width, size.height);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, horizontalWrap);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  const auto bytes = static_cast<GLsizeiptr>(size.area()) * 4;
  for (const auto& buffer : buffers) {
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, buffer.name());
    glBufferData(GL_PIXEL_UNPACK_BUFFER, bytes, nullptr, GL_STREAM_DRAW);
  }
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  gl::check("creating a streamed texture");
}

void SurroundScene::StreamedTexture::upload(const cv::Mat& bgr) {
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, buffers[next].name());
  next = (next + 1) % buffers.size();
  auto* mapped =
      glMapBufferRange(GL_PIXEL_UNPACK_BUFFER, 0, static_cast<GLsizeiptr>(size.area()) * 4,
                       GL_MAP_WRITE_BIT | GL_MAP_INVALIDATE_BUFFER_BIT);
  if (mapped == nullptr) {
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    gl::check("mapping a texture upload buffer");
    throw std::runtime_error("mapping a texture upload buffer failed");
  }
  // Widened to RGBA on the way into the buffer, in place of a plain copy: drivers store RGB8 as
  // four bytes a texel, and their own widening during the upload is the slow part of it
  // (llvmpipe, 2048x1024, measured here: copied as RGB and widened by Mesa 2.0 ms, widened here
  // and copied by Mesa 0.55 ms).
  cv::Mat into(size, CV_8UC4, mapped);
  cv::cvtColor(bgr, into, cv::COLOR_BGR2RGBA);
  glUnmapBuffer(GL_PIXEL_UNPACK_BUFFER);
  glBindTexture(GL_TEXTURE_2D, texture.name());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, size.width, size.height, GL_RGBA, GL_UNSIGNED_BYTE,
                  nullptr);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  gl::check("uploading a texture");
}

SurroundScene::PassPrograms::PassPrograms(const processing::PanoramaGeometry& panorama,
                                          bool panoramaPositions)
    : mesh("surround mesh", kMeshVertex,
           panoramaPositions ? withPanoramaPositions(kMeshFragment) : kMeshFragment),
      car("car", kCarVertex,
          panoramaPositions ? withPanoramaPositions(kCarFragment) : kCarFragment),
      strip("360 strips", kFullViewportVertex,
            panoramaPositions ? withPanoramaPositions(kStripFragment) : kStripFragment),
      meshViewProjection(mesh.uniform("u_viewProjection")),
      carViewProjection(car.uniform("u_viewProjection")),
      stripTangents(strip.uniform("u_tangents")) {
  glUseProgram(strip.name());
  glUniform1f(strip.uniform("u_panoramaTop"), static_cast<float>(panorama.elevationTopRad));
  glUniform1f(strip.uniform("u_panoramaSpan"),
              static_cast<float>(panorama.elevationTopRad - panorama.elevationBottomRad));
}

SurroundScene::SurroundScene(const processing::SurroundMesh& mesh,
                             const processing::PanoramaGeometry& panorama,
                             const processing::VehicleDimensions& car, cv::Size cameraSize)
    : cameraSize_(cameraSize),
      picturePass_(panorama, false),
      positionsPass_(panorama, true),
      pictureProgram_("camera picture", kFullViewportVertex, kPictureFragment),
      guidelineProgram_("guidelines", kGuidelineVertex, kGuidelineFragment),
      guidelineViewProjection_(guidelineProgram_.uniform("u_viewProjection")),
      panoramaTexture_(panorama.size, GL_REPEAT),  // azimuth wraps around
      panoramaSource_(panoramaTexture_.texture.name()),
      cameraTexture_(cameraSize, GL_CLAMP_TO_EDGE),
      meshIndexCount_(static_cast<GLsizei>(mesh.indices.size())) {
  glBindVertexArray(meshArray_.name());
  glBindBuffer(GL_ARRAY_BUFFER, meshVertices_.name());
  glBufferData(GL_ARRAY_BUFFER,
               static_cast<GLsizeiptr>(mesh.vertices.size() * sizeof(processing::MeshVertex)),
               mesh.vertices.data(), GL_STATIC_DRAW);
  constexpr auto kMeshStride = static_cast<GLsizei>(sizeof(processing::MeshVertex));
  attribute(0, 3, kMeshStride, offsetof(processing::MeshVertex, position));
  attribute(1, 2, kMeshStride, offsetof(processing::MeshVertex, uv));
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, meshIndices_.name());
  glBufferData(GL_ELEMENT_ARRAY_BUFFER,
               static_cast<GLsizeiptr>(mesh.indices.size() * sizeof(std::uint32_t)),
               mesh.indices.data(), GL_STATIC_DRAW);

  const CarModel carModel = buildCarModel(car, mesh.innerRadiusM);
  carParts_ = carModel.parts;
  glBindVertexArray(carArray_.name());
  glBindBuffer(GL_ARRAY_BUFFER, carVertices_.name());
  glBufferData(GL_ARRAY_BUFFER,
               static_cast<GLsizeiptr>(carModel.vertices.size() * sizeof(CarVertex)),
               carModel.vertices.data(), GL_STATIC_DRAW);
  constexpr auto kCarStride = static_cast<GLsizei>(sizeof(CarVertex));
  attribute(0, 3, kCarStride, offsetof(CarVertex, position));
  attribute(1, 3, kCarStride, offsetof(CarVertex, normal));
  attribute(2, 3, kCarStride, offsetof(CarVertex, colour));
  attribute(3, 2, kCarStride, offsetof(CarVertex, uv));
  for (const cv::Mat& texture : carModel.textures) carTextures_.push_back(carTexture(texture));
  carTextures_.push_back(carTexture(cv::Mat(1, 1, CV_8UC4, cv::Scalar::all(255))));

  glBindVertexArray(guidelineArray_.name());
  glBindBuffer(GL_ARRAY_BUFFER, guidelineVertices_.name());
  constexpr auto kGuidelineStride = static_cast<GLsizei>(sizeof(GuidelineVertex));
  attribute(0, 3, kGuidelineStride, offsetof(GuidelineVertex, position));
  attribute(1, 3, kGuidelineStride, offsetof(GuidelineVertex, colour));
  glBindVertexArray(0);
  gl::check("setting up the surround scene");
}

void SurroundScene::setGuidelines(std::span<const GuidelineVertex> triangles) {
  glBindBuffer(GL_ARRAY_BUFFER, guidelineVertices_.name());
  const auto bytes = static_cast<GLsizeiptr>(triangles.size_bytes());
  if (triangles.size() > guidelineCapacity_) {
    // Once, when the first (largest) set comes: reserveGuidelines() makes it never happen later.
    glBufferData(GL_ARRAY_BUFFER, bytes, triangles.data(), GL_DYNAMIC_DRAW);
    guidelineCapacity_ = triangles.size();
  } else if (bytes > 0) {
    glBufferSubData(GL_ARRAY_BUFFER, 0, bytes, triangles.data());
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  guidelineCount_ = static_cast<GLsizei>(triangles.size());
  gl::check("uploading the guidelines");
}

void SurroundScene::reserveGuidelines(std::size_t vertices) {
  if (vertices <= guidelineCapacity_) return;
  glBindBuffer(GL_ARRAY_BUFFER, guidelineVertices_.name());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices * sizeof(GuidelineVertex)),
               nullptr, GL_DYNAMIC_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  guidelineCapacity_ = vertices;
  guidelineCount_ = 0;
  gl::check("reserving the guidelines' buffer");
}

void SurroundScene::drawGuidelineTriangles(const cv::Matx44f& viewProjection) const {
  if (guidelineCount_ == 0) return;
  glUseProgram(guidelineProgram_.name());
  glUniformMatrix4fv(guidelineViewProjection_, 1, GL_TRUE, viewProjection.val);
  glBindVertexArray(guidelineArray_.name());
  glDrawArrays(GL_TRIANGLES, 0, guidelineCount_);
}

void SurroundScene::drawCar(const PassPrograms& programs, const cv::Matx44f& viewProjection) const {
  glUseProgram(programs.car.name());
  glUniformMatrix4fv(programs.carViewProjection, 1, GL_TRUE, viewProjection.val);
  glBindVertexArray(carArray_.name());
  for (const CarModel::Part& part : carParts_) {
    glBindTexture(GL_TEXTURE_2D,
                  carTextures_[part.texture < 0 ? carTextures_.size() - 1
                                                : static_cast<std::size_t>(part.texture)]
                      .name());
    glDrawArrays(GL_TRIANGLES, static_cast<GLint>(part.first), static_cast<GLsizei>(part.count));
  }
}

void SurroundScene::drawGuidelines(const cv::Matx44f& viewProjection) const {
  if (guidelineCount_ == 0) return;
  glEnable(GL_DEPTH_TEST);
  // The car in depth alone: it hides the guidelines under it, as in the picture it is laid on.
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  drawCar(picturePass_, viewProjection);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  drawGuidelineTriangles(viewProjection);
  glBindVertexArray(0);
  glDisable(GL_DEPTH_TEST);
}

void SurroundScene::uploadPanorama(const cv::Mat& bgr) {
  requireBgr(bgr, panoramaTexture_.size, "panorama");
  panoramaTexture_.upload(bgr);
}

void SurroundScene::samplePanoramaFrom(GLuint texture) {
  panoramaSource_ = texture != 0 ? texture : panoramaTexture_.texture.name();
}

void SurroundScene::uploadCamera(const cv::Mat& bgr) {
  requireBgr(bgr, cameraTexture_.size, "camera picture");
  cameraTexture_.upload(bgr);
}

void SurroundScene::drawSurround(const cv::Matx44f& viewProjection, Pass pass) const {
  const PassPrograms& programs = this->programs(pass);
  glEnable(GL_DEPTH_TEST);
  glUseProgram(programs.mesh.name());
  glUniformMatrix4fv(programs.meshViewProjection, 1, GL_TRUE, viewProjection.val);
  glBindTexture(GL_TEXTURE_2D, panoramaSource_);
  glBindVertexArray(meshArray_.name());
  glDrawElements(GL_TRIANGLES, meshIndexCount_, GL_UNSIGNED_INT, nullptr);
  // Not where the view samples the panorama: they change with the steering, the view's LUT not.
  if (pass == Pass::kPicture) drawGuidelineTriangles(viewProjection);
  drawCar(programs, viewProjection);
  glBindVertexArray(0);
  glDisable(GL_DEPTH_TEST);
}

void SurroundScene::drawStrips(const cv::Vec2f& stripTangents, Pass pass) const {
  const PassPrograms& programs = this->programs(pass);
  glUseProgram(programs.strip.name());
  glUniform2f(programs.stripTangents, stripTangents[0], stripTangents[1]);
  glBindTexture(GL_TEXTURE_2D, panoramaSource_);
  glBindVertexArray(emptyArray_.name());
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

void SurroundScene::drawCamera() const {
  glUseProgram(pictureProgram_.name());
  glBindTexture(GL_TEXTURE_2D, cameraTexture_.texture.name());
  glBindVertexArray(emptyArray_.name());
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

}  // namespace surroundd::render
