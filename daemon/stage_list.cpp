#include "daemon/stage_list.hpp"

#include <algorithm>
#include <string>

#include <spdlog/spdlog.h>

#include "daemon/stages/calibration_watch_stage.hpp"
#include "daemon/stages/camera_health_stage.hpp"
#include "daemon/stages/mosaic_stage.hpp"
#include "daemon/stages/panorama_stage.hpp"
#include "daemon/stages/recording_stage.hpp"
#include "daemon/stages/stream_output_stage.hpp"
#include "daemon/stages/surround_stage.hpp"

namespace surroundd::daemon {
namespace {

// The format the panorama samples the cameras' frames in: theirs when they all hold one
// (PanoramaStage), else BGR.
PixelFormat cameraFormatOf(const std::vector<std::unique_ptr<capture::CameraStream>>& cameras) {
  if (cameras.empty()) return PixelFormat::kBgr;
  const PixelFormat first = cameras.front()->pixelFormat();
  return std::ranges::all_of(cameras, [&](const auto& c) { return c->pixelFormat() == first; })
             ? first
             : PixelFormat::kBgr;
}

// The V4L2 cameras' frames lent their drivers' buffers where the GPU stitch can import them.
// Only for a GPU that imports them: a CPU stitch would gather its pixels from the driver's
// buffers in place, which on many embedded capture drivers are not cached. The GPU path reads a
// lent frame once, in order, where the driver will not import it after all (its upload's copy,
// in place of capture's); colour correction reads only its seam samples.
void lendCameraBuffers(const Config& config, const SurroundStage& surround,
                       std::vector<std::unique_ptr<capture::CameraStream>>& cameras) {
  const std::string& refusal = surround.dmabufImportRefusal();
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    if (!config.cameras[c].v4l2()) continue;
    const std::string& name = cameras[c]->name();
    const char* why = refusal.empty() ? cameras[c]->lendBuffers() : refusal.c_str();
    if (why == nullptr) {
      spdlog::info("capture: camera '{}': frames lent the driver's buffers, for the GPU to import",
                   name);
    } else {
      spdlog::info("capture: camera '{}': frames copied out of the driver's buffers: {}", name,
                   why);
    }
  }
}

}  // namespace

StageList buildStages(const Config& config, const StageSources& sources) {
  StageList list;
  const auto add = [&]<typename Stage>(std::unique_ptr<Stage> stage) -> Stage& {
    Stage& added = *stage;
    list.stages.push_back(std::move(stage));
    return added;
  };
  add(std::make_unique<CameraHealthStage>(config, sources.cameras, sources.synchronizer));
  add(std::make_unique<RecordingStage>());
  add(std::make_unique<MosaicStage>(config));
  const bool surround = config.shows(OutputStream::kSurround);
  if (surround || config.shows(OutputStream::kPanorama)) {
    auto& panorama = add(std::make_unique<PanoramaStage>(config, sources.pool));
    list.mounts = &add(std::make_unique<CalibrationWatchStage>(config, panorama));
    if (surround) {
      auto& views = add(std::make_unique<SurroundStage>(config, std::move(*sources.renderer.get()),
                                                        panorama, cameraFormatOf(sources.cameras)));
      list.views = &views;
      if (views.stitchesOnGpu()) lendCameraBuffers(config, views, sources.cameras);
    }
  }
  if (!surround && config.processing.backend == ProcessingBackend::kGpu) {
    spdlog::info("processing: cpu (no surround output: the GPU stitch is for the surround views)");
  }
  add(std::make_unique<StreamOutputStage>());
  return list;
}

}  // namespace surroundd::daemon
