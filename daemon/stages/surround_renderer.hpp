#pragma once
// The surround views' renderer: the EGL context and the scene (mesh, car, shaders) they are drawn
// with, opened on a thread of its own while the cameras open and the panorama's table is read
// (openSurroundRenderer()), then handed to the surround stage (surround_stage.hpp) with its
// context current on no thread.

#include <cstddef>
#include <future>
#include <memory>

#include "daemon/config/config.hpp"
#include "render/egl_context.hpp"
#include "render/surround_scene.hpp"

namespace surroundd::daemon {

// What the surround views are drawn with: the EGL context and the scene (mesh, car, shaders).
// Opening it is most of the start-up's fixed cost on llvmpipe (0.4 s: the driver's start and the
// shaders' compiling) and needs nothing the cameras or the panorama's table give, so it runs beside
// them. Its context is current on no thread while it is handed over.
class SurroundRenderer {
 public:
  SurroundRenderer(std::unique_ptr<render::EglContext> context,
                   std::unique_ptr<render::SurroundScene> built);
  // Never taken by a stage (the start-up failed elsewhere): the scene's GL objects are deleted
  // with its context current on this thread.
  ~SurroundRenderer();
  SurroundRenderer(SurroundRenderer&&) = default;
  SurroundRenderer& operator=(SurroundRenderer&&) = default;

  // The context first, so that it outlives the GL objects of the scene.
  std::unique_ptr<render::EglContext> gl;
  std::unique_ptr<render::SurroundScene> scene;
};

// Opens the renderer for `config`'s surround views on a thread of its own; `config` must outlive
// the future's result. Its get() throws RenderError, or std::runtime_error naming the config for
// a mesh that cannot be built.
std::future<std::unique_ptr<SurroundRenderer>> openSurroundRenderer(const Config& config);

// The camera the split view shows beside the surround: render.split_camera, else the first.
std::size_t splitCameraOf(const Config& config);

}  // namespace surroundd::daemon
