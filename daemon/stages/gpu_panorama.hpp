#pragma once
// The panorama stitched and colour-corrected on the GPU (render/gpu_stitcher.hpp), where
// processing.backend comes to it on the renderer (gpu, or auto on a hardware renderer): from each
// set's frames in their own format, as the panorama stage holds them (PanoramaStage::frames()),
// imported from their DMABUFs where the driver allows, else uploaded. The surround views then
// sample it, and the CPU's panorama is made only when something else needs it.
//
// Threads: the renderer's context's, which is the pipeline thread.

#include <cstdint>
#include <string>
#include <vector>

#include <GLES3/gl3.h>

#include "common/pixel_format.hpp"
#include "daemon/config/config.hpp"
#include "daemon/pipeline_stage.hpp"
#include "daemon/stages/panorama_stage.hpp"
#include "render/egl_context.hpp"
#include "render/gpu_stitcher.hpp"
#include "render/gpu_timer.hpp"

namespace surroundd::daemon {

class GpuPanorama {
 public:
  // Set up on `gl` (current on this thread) for `panorama`'s table and colour field and frames in
  // `cameraFormat`, where processing.backend comes to the GPU; logs where the panorama is
  // stitched and why. `panorama` must outlive it.
  GpuPanorama(const Config& config, const render::EglContext& gl, PanoramaStage& panorama,
              PixelFormat cameraFormat);

  // Whether the GPU stitches the panorama (processing.backend as it came out on this renderer).
  bool enabled() const { return stitcher_ != nullptr; }
  // Whether it stitches this set: enabled, and no camera faulty (the CPU marks a faulty camera's
  // part).
  bool stitches(const FrameWork& work) const;
  // Stitches the set the panorama stage was last given, its upload and stitch timed by `timer`,
  // and returns the texture it is in. Frames held in another format than the last set's, or a
  // panorama remounted since (PanoramaStage::generation()), get a stitch set up for them first.
  GLuint stitch(render::GpuTimer& timer);
  // Why the GPU stitch cannot import camera frames from their DMABUFs (render/dmabuf_import.hpp);
  // empty when it can.
  const std::string& dmabufImportRefusal() const { return importRefusal_; }

 private:
  // Which way each camera's lent frames reached the GPU (imported, or uploaded and why), when it
  // changes.
  void sayHowFramesReachTheGpu();

  PanoramaStage& panorama_;
  std::unique_ptr<render::GpuStitcher> stitcher_;  // none: the CPU stitches
  std::string importRefusal_;
  std::vector<char> importSaid_;  // per camera: 0 nothing said, 1 imported, 2 uploaded
  std::uint64_t generation_;      // of the panorama's tables the stitch was set up for
};

}  // namespace surroundd::daemon
