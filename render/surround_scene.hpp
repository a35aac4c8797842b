#pragma once
// What every surround view draws from, on the GPU: the panorama texture (streamed each frame
// through pixel buffer objects), the surround mesh and the car (uploaded once), the split view's
// camera picture, and the shader programs. Built at start-up on the thread of the current
// EglContext; SurroundView draws it.

#include <array>
#include <optional>
#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/panorama_geometry.hpp"
#include "processing/surround_mesh.hpp"
#include "render/car_model.hpp"
#include "render/gl_objects.hpp"
#include "render/guidelines.hpp"
#include "render/shader_program.hpp"
#include "render/view_camera.hpp"

namespace surroundd::render {

class SurroundScene {
 public:
  // `cameraSize` is the size of the pictures the split view shows beside the 3D view.
  SurroundScene(const processing::SurroundMesh& mesh, const processing::PanoramaGeometry& panorama,
                const processing::VehicleDimensions& car, cv::Size cameraSize);

  // 8-bit BGR, of the panorama's size (resp. cameraSize); throws std::invalid_argument otherwise.
  void uploadPanorama(const cv::Mat& bgr);
  void uploadCamera(const cv::Mat& bgr);
  // Samples the panorama from `texture` (RGB, the panorama's size, repeated across azimuth:
  // GpuStitcher's) instead of the uploaded one, from the next draw on; 0 goes back to uploads.
  // The texture must outlive the scene's use of it.
  void samplePanoramaFrom(GLuint texture);
  // The guidelines' triangles, drawn on the ground by the picture pass from now on (none: empty).
  // A buffer of reserveGuidelines() vertices is filled in place: nothing is allocated when they
  // change with the steering.
  void setGuidelines(std::span<const GuidelineVertex> triangles);
  void reserveGuidelines(std::size_t vertices);
  bool hasGuidelines() const { return guidelineCount_ > 0; }

  // What a draw writes: the picture, or where each pixel samples the panorama texture (texture
  // coordinates in red and green, 1 in blue; 0 in blue where the panorama is not shown: the car,
  // the 360 view's rows above and below the panorama).
  enum class Pass { kPicture, kPanoramaPositions };

  // Into the current framebuffer and viewport:
  void drawSurround(const cv::Matx44f& viewProjection,  // mesh and car, depth-tested
                    Pass pass = Pass::kPicture) const;
  void drawStrips(const cv::Vec2f& stripTangents,  // the 360 view
                  Pass pass = Pass::kPicture) const;
  void drawCamera() const;  // the camera picture, filling it
  // The guidelines alone, where the car does not stand over them (for a view drawn once, that
  // lays them over its gathered picture).
  void drawGuidelines(const cv::Matx44f& viewProjection) const;

  cv::Size cameraSize() const { return cameraSize_; }
  cv::Size panoramaSize() const { return panoramaTexture_.size; }

 private:
  // The programs of one pass (the panorama-positions pass compiles the shaders with
  // PANORAMA_POSITIONS defined), and their uniforms.
  struct PassPrograms {
    PassPrograms(const processing::PanoramaGeometry& panorama, bool panoramaPositions);
    ShaderProgram mesh;
    ShaderProgram car;
    ShaderProgram strip;
    GLint meshViewProjection;
    GLint carViewProjection;
    GLint stripTangents;
  };
  const PassPrograms& programs(Pass pass) const {
    return pass == Pass::kPicture ? picturePass_ : positionsPass_;
  }
  void drawCar(const PassPrograms& programs, const cv::Matx44f& viewProjection) const;
  void drawGuidelineTriangles(const cv::Matx44f& viewProjection) const;

  // A texture fed through two pixel buffers in turn, so that filling one does not wait for the
  // transfer of the other.
  struct StreamedTexture {
    StreamedTexture(cv::Size size, GLint horizontalWrap);
    void upload(const cv::Mat& bgr);

    cv::Size size;
    gl::Texture texture;
    std::array<gl::Buffer, 2> buffers;
    std::size_t next = 0;
  };

  cv::Size cameraSize_;
  PassPrograms picturePass_;
  PassPrograms positionsPass_;
  ShaderProgram pictureProgram_;
  ShaderProgram guidelineProgram_;
  GLint guidelineViewProjection_;
  StreamedTexture panoramaTexture_;
  GLuint panoramaSource_;  // what the panorama passes sample: panoramaTexture_'s, or a stitcher's
  StreamedTexture cameraTexture_;
  gl::VertexArray meshArray_;
  gl::Buffer meshVertices_;
  gl::Buffer meshIndices_;
  GLsizei meshIndexCount_;
  gl::VertexArray carArray_;
  gl::Buffer carVertices_;
  std::vector<CarModel::Part> carParts_;
  std::vector<gl::Texture> carTextures_;  // the model's, then one white texel for parts without
  gl::VertexArray emptyArray_;            // full-screen passes make their vertices from gl_VertexID
  gl::VertexArray guidelineArray_;
  gl::Buffer guidelineVertices_;
  std::size_t guidelineCapacity_ = 0;
  GLsizei guidelineCount_ = 0;
};

}  // namespace surroundd::render
