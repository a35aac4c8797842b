#include "daemon/stages/surround_stage.hpp"

#include <algorithm>

#include <opencv2/core.hpp>

namespace surroundd::daemon {
namespace {

std::unique_ptr<render::EglContext> madeCurrent(std::unique_ptr<render::EglContext> gl) {
  gl->makeCurrent();
  return gl;
}

// What the guidelines show for the vehicle's signals: reversing, with render.guidelines reverse or
// always; going forward (drive, neutral), with always; none else.
std::optional<render::GuidelinePose> guidelinePose(GuidelineMode mode,
                                                   const vehicle::VehicleSignals& signals) {
  using vehicle::Gear;
  const bool reverse = signals.gear == Gear::kReverse;
  const bool forward = signals.gear == Gear::kDrive || signals.gear == Gear::kNeutral;
  if (mode == GuidelineMode::kOff || !(reverse || (forward && mode == GuidelineMode::kAlways))) {
    return std::nullopt;
  }
  return render::GuidelinePose{reverse ? render::Travel::kReverse : render::Travel::kForward,
                               signals.steeringDeg};
}

}  // namespace

SurroundStage::SurroundStage(const Config& config, SurroundRenderer renderer,
                             PanoramaStage& panorama, PixelFormat cameraFormat)
    : views_(config.render.views),
      gl_(madeCurrent(std::move(renderer.gl))),
      scene_(std::move(renderer.scene)),
      panorama_(panorama.picture()),
      gpu_(config, *gl_, panorama, cameraFormat),
      fixed_(config, config.render.viewLut && !gpu_.enabled(), panorama),
      guidelineMode_(config.render.guidelines),
      splitCamera_(splitCameraOf(config)) {
  if (guidelineMode_ != GuidelineMode::kOff) {
    guides_.emplace(*scene_, config.car(), config.render.guide);
  }
}

std::unique_ptr<render::SurroundView> SurroundStage::makeView(cv::Size size, ViewKind view) {
  // The views go before the stage (the pipeline destroys its outputs first): they may borrow the
  // timer.
  return std::make_unique<render::SurroundView>(*scene_, size, view, views_, &gpuTimer_);
}

void SurroundStage::prepare(PipelineOutputs& outputs, bool waitForTables) {
  fixed_.prepare(outputs, waitForTables);
}

void SurroundStage::uploadPanorama() {
  scene_->samplePanoramaFrom(0);
  const render::GpuTimer::Scope timed(&gpuTimer_, render::GpuStep::kUpload);
  scene_->uploadPanorama(panorama_);
  panoramaOnGpu_ = false;
}

void SurroundStage::collectGpuTimes() {
  for (const auto& reading : gpuTimer_.collect()) {
    gpuTimes_[static_cast<std::size_t>(reading.step)].record(reading.time);
  }
}

bool SurroundStage::needs(Need what, const FrameWork& work) const {
  if (what != Need::kPanorama || gpu_.stitches(work)) return false;
  return std::ranges::any_of(work.outputs.pictures(), [&](const auto& output) {
    // A view with a read-back pending is drawn (or its table started) after it is collected;
    // a fixed view whose table has just been made is taken into use in process(), so this set
    // still has the panorama.
    return output.view && output.sink && (output.view->pending() || !fixed_.shown(output));
  });
}

void SurroundStage::setVehicleSignals(const vehicle::VehicleSignals& signals) {
  if (guides_) guides_->show(guidelinePose(guidelineMode_, signals));
}

bool SurroundStage::anyView(const PipelineOutputs& outputs) {
  return std::ranges::any_of(outputs.pictures(),
                             [](const auto& output) { return output.view && output.sink; });
}

void SurroundStage::process(FrameWork& work, StageTimes& times) {
  deliver(work.outputs, &times);
  collectGpuTimes();
  lastStreamTime_ = work.streamTime;
  // Drawn views or not, as the CPU's panorama is made for them: the run's end may draw one again.
  bool panoramaUploaded = false;
  if (gpu_.stitches(work) && anyView(work.outputs)) {
    scene_->samplePanoramaFrom(gpu_.stitch(gpuTimer_));
    panoramaOnGpu_ = true;
    panoramaUploaded = true;
    times.lap(Stage::kStitch);
  }
  bool cameraUploaded = false;
  bool anyFixed = false;
  for (auto& output : work.outputs.pictures()) {
    if (!output.view || !output.sink) continue;
    const bool wanted = output.sink->wantsFrame(work.streamTime);
    work.outputs.guarded(output, [&] {
      if (FixedViews::View* fixed = fixed_.ready(output)) {
        // Without a panorama this set, also when not wanted: the run's end hands over the last
        // set's picture, and there is no panorama to draw it from.
        if (!wanted && work.panorama != nullptr) return;
        fixed_.draw(*fixed, output, work, times, guides_ ? &*guides_ : nullptr, wanted);
        anyFixed = anyFixed || wanted;
        return;
      }
      if (!wanted) return;
      if (!panoramaUploaded) {
        uploadPanorama();
        panoramaUploaded = true;
      }
      drawView(output, work, cameraUploaded);
    });
  }
  times.lap(Stage::kRender);
  if (!anyFixed) return;
  fixed_.handOver(work);
  times.lap(Stage::kOutput);
}

void SurroundStage::drawView(PipelineOutputs::PictureOutput& output, FrameWork& work,
                             bool& cameraUploaded) {
  if (output.view->view() == ViewKind::kSplit && !cameraUploaded) {
    if (const cv::Mat* camera = work.bgr(splitCamera_); camera != nullptr) {
      scene_->uploadCamera(*camera);
      cameraUploaded = true;
    }
  }
  const double timeS = std::chrono::duration<double>(work.streamTime).count();
  if (output.sink->presentsViews()) {
    // Shown at once: on a GPU the swap only queues the picture's copy to the screen.
    output.view->draw(timeS, render::SurroundView::ReadBack::kNo);
    work.outputs.present(output, work.streamTime, work.origin, output.view->drawn());
    return;
  }
  output.view->draw(timeS);
  output.pendingTime = work.streamTime;
  output.pendingOrigin = work.origin;
}

void SurroundStage::deliver(PipelineOutputs& outputs, StageTimes* times, Pending which) {
  for (auto& output : outputs.pictures()) {
    if (!output.view || !output.view->pending()) continue;
    if (which == Pending::kFinished && !output.view->finished()) continue;
    if (times != nullptr) times->skip();
    cv::Mat picture;
    outputs.guarded(output, [&] { picture = output.view->collect(); });
    if (times != nullptr) times->lap(Stage::kReadBack);
    if (!picture.empty()) {
      outputs.handOver(output, picture, output.pendingTime, output.pendingOrigin,
                       output.view->drawn());
      fixed_.firstPictureOut();
    }
    if (times != nullptr) times->lap(Stage::kOutput);
  }
}

void SurroundStage::finish(PipelineOutputs& outputs) {
  deliver(outputs, nullptr);
  collectGpuTimes();
}

cv::Mat SurroundStage::redraw(PipelineOutputs::PictureOutput& output) {
  if (const cv::Mat* fixed = fixed_.pictureOf(output, lastStreamTime_)) return *fixed;
  if (!panoramaOnGpu_) uploadPanorama();
  output.view->draw(std::chrono::duration<double>(lastStreamTime_).count());
  return output.view->collect();
}

void SurroundStage::report(PipelineReport& report) const {
  report.renderer = description();
  report.gpuTimed = gpuTimer_.available();
  report.gpuSteps = gpuTimes_;
}

}  // namespace surroundd::daemon
