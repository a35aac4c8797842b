#include "daemon/stages/surround_stage.hpp"

#include <algorithm>
#include <limits>
#include <span>
#include <string_view>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "daemon/config/output_type.hpp"
#include "daemon/config/panorama_setup.hpp"
#include "daemon/pipeline_ends.hpp"
#include "processing/stitch/i420_picture.hpp"
#include "render/dmabuf_import.hpp"
#include "render/render_error.hpp"

namespace surroundd::daemon {
namespace {

// Whether processing.backend comes to the GPU on this renderer, and why.
std::pair<bool, std::string_view> gpuBackendOf(const Config& config, const render::EglContext& gl) {
  const ProcessingBackend backend = config.processing.backend;
  if (backend == ProcessingBackend::kCpu) return {false, "processing.backend: cpu"};
  if (backend == ProcessingBackend::kAuto && gl.software()) {
    return {false, "auto: the renderer runs on the CPU, where the CPU path is faster"};
  }
  if (config.colour.method == ColourMethod::kGain) {
    return {false, "gain compensation is applied on the CPU only"};
  }
  if (backend == ProcessingBackend::kAuto) return {true, "auto: a hardware renderer"};
  return {true, gl.software() ? "processing.backend: gpu, on a renderer that runs on the CPU "
                                "(slower than the CPU path)"
                              : "processing.backend: gpu"};
}

std::unique_ptr<render::EglContext> madeCurrent(std::unique_ptr<render::EglContext> gl) {
  gl->makeCurrent();
  return gl;
}

}  // namespace

SurroundStage::SurroundStage(const Config& config, SurroundRenderer renderer,
                             PanoramaStage& panorama, PixelFormat cameraFormat)
    : views_(config.render.views),
      gl_(madeCurrent(std::move(renderer.gl))),
      scene_(std::move(renderer.scene)),
      panoramaStage_(panorama),
      panorama_(panorama.picture()),
      viewLut_(config.render.viewLut),
      guidelineMode_(config.render.guidelines),
      guide_(config.render.guide),
      car_(config.car()),
      splitCamera_(splitCameraOf(config)) {
  if (guidelineMode_ != GuidelineMode::kOff) {
    const std::size_t vertices = render::maxGuidelineVertices(guide_);
    guideVertices_.reserve(vertices);
    scene_->reserveGuidelines(vertices);
  }
  auto [gpu, why] = gpuBackendOf(config, *gl_);
  if (gpu) {
    try {
      gpu_ = std::make_unique<render::GpuStitcher>(panorama.lut(), cameraFormat, panorama.pool());
      gpu_->correctWith(panorama.colourField());
    } catch (const render::RenderError& e) {
      spdlog::warn("processing: the GPU cannot stitch the panorama: {}", e.what());
      gpu_.reset();
      why = "the GPU stitch could not be set up";
    }
  }
  importSaid_.resize(panorama.lut().cameraSizes.size());
  importRefusal_ =
      gpu_ ? render::DmabufImport(cameraFormat, panorama.lut().cameraSizes.at(0)).refusal()
           : "the panorama is stitched on the CPU";
  spdlog::info("processing: {} ({}){}", gpu_ ? "gpu" : "cpu", why,
               gpu_ ? fmt::format(", frames uploaded as {}", toString(cameraFormat)) : "");
}

std::unique_ptr<render::SurroundView> SurroundStage::makeView(cv::Size size, ViewKind view) {
  // The views go before the stage (the pipeline destroys its outputs first): they may borrow the
  // timer.
  return std::make_unique<render::SurroundView>(*scene_, size, view, views_, &gpuTimer_);
}

SurroundStage::FixedView* SurroundStage::fixedView(render::SurroundView& view) {
  if (!viewLut_ || gpu_ || !view.settlesStill()) return nullptr;
  const ViewKind kind = view.view();
  const auto key = std::pair{static_cast<const render::SurroundView*>(&view), kind};
  const auto known = fixedViews_.find(key);
  if (known == fixedViews_.end()) {
    if (!tablesAfterFirstPicture_) startFixedView(view, fixedViews_[key]);
    return nullptr;
  }
  FixedView& fixed = known->second;
  if (fixed.building.valid()) {
    if (fixed.building.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
      return nullptr;
    }
    try {
      fixed.view = fixed.building.get();
      // Drawn now, not with the map: each takes its own set's time.
      fixed.overlay = view.stillPicture(0);
      fixed.picture = fixed.overlay.clone();
      spdlog::info(
          "render: the {} view {}x{} is gathered from the camera frames through its own "
          "look-up table (made in {:.2f} s: {:.2f} s mapping it with OpenGL, {:.2f} s composing "
          "it beside the sets)",
          toString(kind), view.size().width, view.size().height,
          (fixed.mappedIn + fixed.view->composedIn()).count(), fixed.mappedIn.count(),
          fixed.view->composedIn().count());
    } catch (const std::exception& e) {
      fixed.view.reset();
      spdlog::warn("render: the {} view is drawn by OpenGL: {}", toString(kind), e.what());
    }
  }
  // Until a switch to it has ended, the renderer draws the way there.
  return fixed.view && !view.moves() ? &fixed : nullptr;
}

SurroundStage::FixedView* SurroundStage::fixedViewFor(PipelineOutputs::PictureOutput& output) {
  return output.sink->presentsViews() ? nullptr : fixedView(*output.view);
}

const SurroundStage::FixedView* SurroundStage::shownFixedView(
    const PipelineOutputs::PictureOutput& output) const {
  const render::SurroundView& view = *output.view;
  if (output.sink->presentsViews() || !viewLut_ || gpu_ || view.moves()) return nullptr;
  const auto known = fixedViews_.find({&view, view.view()});
  return known != fixedViews_.end() && known->second.view ? &known->second : nullptr;
}

void SurroundStage::startFixedView(render::SurroundView& view, FixedView& fixed) {
  // The map here, on the context's thread (a tenth of a second on llvmpipe the first time); the
  // composition on a thread of its own, while OpenGL draws the view (and the switch to it); the
  // car and background when it is taken into use.
  const auto start = std::chrono::steady_clock::now();
  try {
    cv::Mat positions = view.panoramaPositions(0);
    cv::bitwise_not(render::SurroundView::panoramaShown(positions), fixed.overlayMask);
    // The split view's camera half is the camera's own picture, scaled in each set: nothing of
    // the panorama is gathered or corrected there.
    if (const auto camera = view.cameraArea()) {
      fixed.overlayMask(*camera).setTo(0);
      positions(*camera).setTo(cv::Scalar::all(std::numeric_limits<float>::quiet_NaN()));
    }
    fixed.mappedIn = std::chrono::steady_clock::now() - start;
    fixed.building = panoramaStage_.buildView(positions);
  } catch (const render::RenderError& e) {
    spdlog::warn("render: the {} view is drawn by OpenGL: {}", toString(view.view()), e.what());
  }
}

void SurroundStage::prepare(PipelineOutputs& outputs, bool waitForTables) {
  if (!waitForTables) {
    // Mapping a view and composing its table take the cores that the first picture needs.
    tablesAfterFirstPicture_ = true;
    return;
  }
  const auto eachFirstView = [&] {
    for (auto& output : outputs.pictures()) {
      if (output.view && output.sink) (void)fixedViewFor(output);
    }
  };
  eachFirstView();  // starts the tables
  if (!waitForTables) return;
  for (auto& [key, fixed] : fixedViews_) {
    if (fixed.building.valid()) fixed.building.wait();
  }
  eachFirstView();  // takes them into use
}

bool SurroundStage::gpuStitches(const FrameWork& work) const {
  if (!gpu_) return false;
  const auto faults = std::span(work.faults).first(work.set.cameraCount);
  return std::ranges::none_of(faults, [](const char* fault) { return fault != nullptr; });
}

void SurroundStage::stitchOnGpu() {
  const PixelFormat format = panoramaStage_.frameFormat();
  if (gpu_->format() != format) {
    spdlog::info("processing: the frames come in {}, not {}: the GPU stitch is set up for them",
                 toString(format), toString(gpu_->format()));
    gpu_ =
        std::make_unique<render::GpuStitcher>(panoramaStage_.lut(), format, panoramaStage_.pool());
    gpu_->correctWith(panoramaStage_.colourField());
  }
  {
    const render::GpuTimer::Scope timed(&gpuTimer_, render::GpuStep::kUpload);
    gpu_->upload(panoramaStage_.frames(), panoramaStage_.dmabufs());
  }
  sayHowFramesReachTheGpu();
  {
    const render::GpuTimer::Scope timed(&gpuTimer_, render::GpuStep::kStitch);
    gpu_->stitch();
  }
  scene_->samplePanoramaFrom(gpu_->panorama());
  panoramaOnGpu_ = true;
}

void SurroundStage::sayHowFramesReachTheGpu() {
  const auto& dmabufs = panoramaStage_.dmabufs();
  for (std::size_t c = 0; c < dmabufs.size(); ++c) {
    if (dmabufs[c].planes == 0) continue;
    const char way = gpu_->imported(c) ? 1 : 2;
    if (importSaid_[c] == way) continue;
    importSaid_[c] = way;
    const std::string& name = panoramaStage_.rig().cameras[c].name;
    if (way == 1) {
      spdlog::info("processing: camera '{}': frames taken from their DMABUFs, with no copy", name);
    } else {
      spdlog::warn("processing: camera '{}': frames uploaded through pixel buffers: {}", name,
                   gpu_->importRefusal(c));
    }
  }
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
  if (what != Need::kPanorama || gpuStitches(work)) return false;
  return std::ranges::any_of(work.outputs.pictures(), [&](const auto& output) {
    // A view with a read-back pending is drawn (or its table started) after it is collected;
    // a fixed view whose table has just been made is taken into use in process(), so this set
    // still has the panorama.
    return output.view && output.sink &&
           (output.view->pending() || shownFixedView(output) == nullptr);
  });
}

void SurroundStage::setVehicleSignals(const vehicle::VehicleSignals& signals) {
  using vehicle::Gear;
  std::optional<std::pair<render::Travel, long>> shown;
  const bool reverse = signals.gear == Gear::kReverse;
  const bool forward = signals.gear == Gear::kDrive || signals.gear == Gear::kNeutral;
  if (guidelineMode_ != GuidelineMode::kOff &&
      (reverse || (forward && guidelineMode_ == GuidelineMode::kAlways))) {
    shown = std::pair{reverse ? render::Travel::kReverse : render::Travel::kForward,
                      std::lround(signals.steeringDeg * 10)};
  }
  if (shown == guidesShown_) return;
  guidesShown_ = shown;
  guideVertices_.clear();
  if (shown) {
    render::guidelines(car_, guide_, shown->first, static_cast<double>(shown->second) / 10,
                       guideVertices_);
  }
  scene_->setGuidelines(guideVertices_);
  ++guidesVersion_;
}

void SurroundStage::layGuidelines(render::SurroundView& view, FixedView& fixed) {
  if (fixed.guidesVersion != guidesVersion_) {
    // Drawn by OpenGL and read back once per change of steering, not per set.
    view.guidelineLayer(0).copyTo(fixed.guides);
    cv::cvtColor(fixed.guides, fixed.guidesGrey, cv::COLOR_BGR2GRAY);
    cv::threshold(fixed.guidesGrey, fixed.guidesMask, 0, 255, cv::THRESH_BINARY);
    fixed.guidesVersion = guidesVersion_;
  }
  fixed.guides.copyTo(fixed.picture, fixed.guidesMask);
}

void SurroundStage::process(FrameWork& work, StageTimes& times) {
  deliver(work.outputs, &times);
  collectGpuTimes();
  lastStreamTime_ = work.streamTime;
  // Drawn views or not, as the CPU's panorama is made for them: the run's end may draw one again.
  bool panoramaUploaded = false;
  if (gpuStitches(work) && std::ranges::any_of(work.outputs.pictures(), [](const auto& output) {
        return output.view && output.sink;
      })) {
    stitchOnGpu();
    panoramaUploaded = true;
    times.lap(Stage::kStitch);
  }
  bool cameraUploaded = false;
  bool anyFixed = false;
  for (auto& output : work.outputs.pictures()) {
    if (!output.view || !output.sink) continue;
    const bool wanted = output.sink->wantsFrame(work.streamTime);
    work.outputs.guarded(output, [&] {
      if (FixedView* fixed = fixedViewFor(output)) {
        // Without a panorama this set, also when not wanted: the run's end hands over the last
        // set's picture, and there is no panorama to draw it from.
        if (!wanted && work.panorama != nullptr) return;
        times.lap(Stage::kRender);  // the views drawn before this one
        // The car, the background and the split view's camera go where the view shows no
        // panorama, before the correction, which leaves those pixels as they are; the guidelines
        // over the corrected picture.
        panoramaStage_.gather(*fixed->view, fixed->picture);
        fixed->overlay.copyTo(fixed->picture, fixed->overlayMask);
        // As the renderer samples it (bilinear, pixel centres at halves); a missing frame leaves
        // the last one shown.
        const auto area = output.view->cameraArea();
        if (const cv::Mat* camera = area ? work.bgr(splitCamera_) : nullptr; camera != nullptr) {
          cv::Mat into = fixed->picture(*area);
          cv::resize(*camera, into, area->size(), 0, 0, cv::INTER_LINEAR);
        }
        times.lap(Stage::kStitch);
        // An encoder's picture is made in I420 as it is corrected; with guidelines, after them.
        const bool guided = scene_->hasGuidelines();
        fixed->inI420 = output.sink->takesI420();
        panoramaStage_.correct(*fixed->view, work, fixed->picture,
                               fixed->inI420 && !guided ? &fixed->i420 : nullptr);
        if (guided) {
          layGuidelines(*output.view, *fixed);
          if (fixed->inI420) {
            processing::bgrToI420(fixed->picture, fixed->i420, panoramaStage_.pool());
          }
        }
        times.lap(Stage::kCorrect);
        fixed->drawnAt = work.streamTime;
        fixed->handOver = wanted;
        anyFixed = anyFixed || wanted;
        return;
      }
      if (!wanted) return;
      if (!panoramaUploaded) {
        uploadPanorama();
        panoramaUploaded = true;
      }
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
    });
  }
  times.lap(Stage::kRender);
  if (!anyFixed) return;
  for (auto& output : work.outputs.pictures()) {
    if (!output.view) continue;
    const auto fixed = fixedViews_.find({output.view.get(), output.view->view()});
    if (fixed == fixedViews_.end() || !fixed->second.handOver) continue;
    fixed->second.handOver = false;
    // Gathered in this set, with the view settled: a fixed view does not move.
    const FixedView& drawn = fixed->second;
    work.outputs.handOver(output, drawn.inI420 ? drawn.i420 : drawn.picture, work.streamTime,
                          work.origin, render::DrawnPicture{PipelineOutputs::Clock::now(), true},
                          &drawn.picture);
  }
  times.lap(Stage::kOutput);
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
      tablesAfterFirstPicture_ = false;
    }
    if (times != nullptr) times->lap(Stage::kOutput);
  }
}

void SurroundStage::finish(PipelineOutputs& outputs) {
  deliver(outputs, nullptr);
  collectGpuTimes();
}

cv::Mat SurroundStage::redraw(PipelineOutputs::PictureOutput& output) {
  const auto fixed = fixedViews_.find({output.view.get(), output.view->view()});
  if (fixed != fixedViews_.end() && fixed->second.view &&
      fixed->second.drawnAt == lastStreamTime_) {
    return fixed->second.picture;
  }
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
