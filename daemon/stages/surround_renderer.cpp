#include "daemon/stages/surround_renderer.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include <spdlog/spdlog.h>

#include "daemon/config/output_type.hpp"
#include "daemon/config/panorama_setup.hpp"
#include "daemon/pipeline_ends.hpp"
#include "render/render_error.hpp"

namespace surroundd::daemon {
namespace {

// The renderer's context: on the display of an output that shows the views on the GPU
// (OutputType::openRenderer: an egl window's X server, an egl display's card), else on
// render.platform. An output's
// display that cannot be opened leaves the renderer on render.platform, and that output failing.
std::unique_ptr<render::EglContext> rendererContext(const Config& config) {
  for (const OutputConfig& output : config.outputs) {
    const OutputType& type = outputTypeOf(output);
    if (!type.openRenderer || output.stream != OutputStream::kSurround) continue;
    try {
      if (auto gl = type.openRenderer(output)) {
        spdlog::info(
            "render: on the {} platform of the {} output, which shows the views through EGL",
            render::toString(gl->platform()), type.name);
        return gl;
      }
    } catch (const render::RenderError& e) {
      spdlog::error("render: the {} output cannot have the renderer: {}; it renders on {}",
                    type.name, e.what(), render::toString(config.render.platform));
    }
  }
  return std::make_unique<render::EglContext>(config.render.platform);
}

}  // namespace

std::size_t splitCameraOf(const Config& config) {
  const auto names = cameraNames(config);
  const auto split = std::ranges::find(names, config.render.splitCamera);
  return split == names.end() ? 0 : static_cast<std::size_t>(split - names.begin());
}

SurroundRenderer::SurroundRenderer(std::unique_ptr<render::EglContext> context,
                                   std::unique_ptr<render::SurroundScene> built)
    : gl(std::move(context)), scene(std::move(built)) {}

SurroundRenderer::~SurroundRenderer() {
  if (!scene || !gl) return;
  try {
    gl->makeCurrent();
  } catch (const render::RenderError& e) {
    spdlog::warn("render: the scene is left to its context's end: {}", e.what());
  }
}

std::future<std::unique_ptr<SurroundRenderer>> openSurroundRenderer(const Config& config) {
  // spdlog's registry is made by the first thread that logs, under a guard inside the library that
  // ThreadSanitizer cannot see: made here, before the thread starts, where nothing has logged yet
  // (a test's pipeline), it is no race to report between that thread's lines and the cameras'.
  spdlog::default_logger_raw();
  return std::async(std::launch::async, [&config] {
    auto gl = rendererContext(config);
    spdlog::info("render: {}", gl->description());
    const processing::PanoramaSettings settings = panoramaSettings(config);
    processing::SurroundMesh mesh;
    try {
      mesh = processing::buildSurroundMesh(meshSettings(config), settings.geometry);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(fmt::format("{}: {}", config.file.string(), e.what()));
    }
    const std::size_t split = splitCameraOf(config);
    auto renderer = std::make_unique<SurroundRenderer>(
        std::move(gl), std::make_unique<render::SurroundScene>(
                           mesh, settings.geometry, config.car(),
                           config.cameras.at(split).calibration.intrinsics.imageSize));
    spdlog::info("render: {} mesh of {} triangles, split view shows '{}'",
                 config.mesh.model == MeshModel::kBowl   ? "bowl"
                 : config.mesh.model == MeshModel::kFlat ? "flat"
                                                         : "sphere360",
                 mesh.indices.size() / 3, cameraNames(config)[split]);
    renderer->gl->release();
    return renderer;
  });
}

}  // namespace surroundd::daemon
