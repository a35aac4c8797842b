#include "daemon/stages/surround_stage.hpp"

#include <algorithm>

#include <spdlog/spdlog.h>

#include "daemon/panorama_setup.hpp"
#include "daemon/pipeline_ends.hpp"

namespace surroundd::daemon {

SurroundStage::SurroundStage(const Config& config, const PanoramaStage& panorama)
    : views_(config.render.views), gl_(config.render.platform), panorama_(panorama.picture()) {
  spdlog::info("render: {}", gl_.description());
  const processing::PanoramaSettings settings = panoramaSettings(config);
  processing::SurroundMesh mesh;
  try {
    mesh = processing::buildSurroundMesh(meshSettings(config), settings.geometry);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(fmt::format("{}: {}", config.file.string(), e.what()));
  }
  const auto names = cameraNames(config);
  const auto split = std::ranges::find(names, config.render.splitCamera);
  splitCamera_ = split == names.end() ? 0 : static_cast<std::size_t>(split - names.begin());
  scene_ = std::make_unique<render::SurroundScene>(mesh, settings.geometry, config.render.car,
                                                   panorama.lut().cameraSizes.at(splitCamera_));
  spdlog::info("render: {} mesh of {} triangles, split view shows '{}'",
               config.mesh.model == MeshModel::kBowl   ? "bowl"
               : config.mesh.model == MeshModel::kFlat ? "flat"
                                                       : "sphere360",
               mesh.indices.size() / 3, names[splitCamera_]);
}

std::unique_ptr<render::SurroundView> SurroundStage::makeView(cv::Size size, ViewKind view) const {
  return std::make_unique<render::SurroundView>(*scene_, size, view, views_);
}

void SurroundStage::process(FrameWork& work, StageTimes& times) {
  deliver(work.outputs, &times);
  lastStreamTime_ = work.streamTime;
  bool panoramaUploaded = false;
  bool cameraUploaded = false;
  for (auto& output : work.outputs.pictures()) {
    if (!output.view || !output.sink || !output.sink->wantsFrame(work.streamTime)) continue;
    work.outputs.guarded(output, [&] {
      if (!panoramaUploaded) {
        scene_->uploadPanorama(panorama_);
        panoramaUploaded = true;
      }
      const capture::Frame* camera = work.set.frame(splitCamera_);
      if (output.view->view() == ViewKind::kSplit && !cameraUploaded && camera != nullptr) {
        scene_->uploadCamera(camera->image);
        cameraUploaded = true;
      }
      output.view->draw(std::chrono::duration<double>(work.streamTime).count());
      output.pendingTime = work.streamTime;
      output.pendingOrigin = work.origin;
    });
  }
  times.lap(Stage::kRender);
}

void SurroundStage::deliver(PipelineOutputs& outputs, StageTimes* times) {
  for (auto& output : outputs.pictures()) {
    if (!output.view || !output.view->pending()) continue;
    if (times != nullptr) times->skip();
    cv::Mat picture;
    outputs.guarded(output, [&] { picture = output.view->collect(); });
    if (times != nullptr) times->lap(Stage::kReadBack);
    if (!picture.empty()) {
      outputs.handOver(output, picture, output.pendingTime, output.pendingOrigin);
    }
    if (times != nullptr) times->lap(Stage::kOutput);
  }
}

void SurroundStage::finish(PipelineOutputs& outputs) { deliver(outputs, nullptr); }

cv::Mat SurroundStage::redraw(PipelineOutputs::PictureOutput& output) {
  scene_->uploadPanorama(panorama_);
  output.view->draw(std::chrono::duration<double>(lastStreamTime_).count());
  return output.view->collect();
}

}  // namespace surroundd::daemon
