#pragma once
// The surround views: the panorama textured onto the bowl / flat / 360 mesh around the car model
// (render/surround_scene.hpp), drawn with OpenGL ES into each surround output's own view. A view's
// picture is drawn while the next set is stitched and collected when that set comes, so each
// output gets it one set later; or sooner, when the pipeline has no set to work on and the picture
// is finished (idle()). The last one goes out when the run ends.
//
// Made of three parts, each in its own file: the views that do not move, gathered through tables
// of their own rather than drawn per set (fixed_views.hpp); the panorama stitched on the GPU where
// processing.backend chooses it (gpu_panorama.hpp), which every view is then drawn from by
// OpenGL, the CPU's panorama made only when something needs it (an output of the panorama, or a
// set with a faulty camera, whose part the CPU marks); and the parking guidelines, a layer of
// every view (render/guideline_layer.hpp).
//
// Threads: the renderer (its EGL context and scene) is opened on a thread of its own
// (openSurroundRenderer()) while the cameras open and the panorama's table is read, and handed to
// the stage with its context current on no thread; the stage makes it current on the thread that
// constructs it, which must be the one that runs it.

#include <array>
#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "daemon/config/config.hpp"
#include "daemon/duration_histogram.hpp"
#include "daemon/pipeline_stage.hpp"
#include "daemon/stages/fixed_views.hpp"
#include "daemon/stages/gpu_panorama.hpp"
#include "daemon/stages/panorama_stage.hpp"
#include "daemon/stages/surround_renderer.hpp"
#include "daemon/surround_views.hpp"
#include "render/egl_context.hpp"
#include "render/gpu_timer.hpp"
#include "render/guideline_layer.hpp"
#include "render/surround_scene.hpp"
#include "render/surround_view.hpp"
#include "vehicle/vehicle_signals.hpp"

namespace surroundd::daemon {

class SurroundStage final : public PipelineStage, public SurroundViews {
 public:
  // Draws with `renderer` (openSurroundRenderer(config)), its context made current here;
  // `panorama` must outlive the stage. The GPU stitch, where processing.backend chooses it, is
  // built for frames held in `cameraFormat` (and built again should a set's frames come in
  // another). Throws RenderError.
  SurroundStage(const Config& config, SurroundRenderer renderer, PanoramaStage& panorama,
                PixelFormat cameraFormat);

  // SurroundViews (daemon/surround_views.hpp).
  std::unique_ptr<render::SurroundView> makeView(cv::Size size, ViewKind view) override;
  void prepare(PipelineOutputs& outputs, bool waitForTables) override;
  cv::Mat redraw(PipelineOutputs::PictureOutput& output) override;
  render::EglContext& context() override { return *gl_; }
  // The guidelines are drawn again only when they change by a tenth of a degree or more.
  void setVehicleSignals(const vehicle::VehicleSignals& signals) override;

  // Whether this set needs the CPU's panorama (Need::kPanorama): a view drawn from it (on the
  // CPU backend, or in a set the GPU does not stitch) that is not yet gathered through its own
  // table.
  bool needs(Need what, const FrameWork& work) const override;
  // Each output's view that does not move starts being mapped here the first time it is shown (a
  // view switched to, as the switch begins), and is gathered through its table once made.
  void process(FrameWork& work, StageTimes& times) override;
  void finish(PipelineOutputs& outputs) override;
  // Hands over the pictures whose drawing has finished, so that a picture goes out as soon as it
  // is drawn rather than when the next set comes.
  void idle(PipelineOutputs& outputs, StageTimes& times) override {
    deliver(outputs, &times, Pending::kFinished);
  }
  // The renderer, and the GPU's times of its steps.
  void report(PipelineReport& report) const override;

  // The renderer, and where the panorama is stitched when that is the GPU.
  std::string description() const {
    return stitchesOnGpu() ? gl_->description() + "; panorama stitched on the GPU"
                           : gl_->description();
  }
  // Whether the GPU stitches the panorama (processing.backend as it came out on this renderer).
  bool stitchesOnGpu() const { return gpu_.enabled(); }
  // Why the GPU stitch cannot import camera frames from their DMABUFs (render/dmabuf_import.hpp);
  // empty when it can.
  const std::string& dmabufImportRefusal() const { return gpu_.dmabufImportRefusal(); }

 private:
  enum class Pending { kAll, kFinished };
  // Hands each view's pending picture (the previous set's; or only those finished) to its output.
  void deliver(PipelineOutputs& outputs, StageTimes* times, Pending which = Pending::kAll);
  // Whether any output shows a surround view.
  static bool anyView(const PipelineOutputs& outputs);
  // Draws `output`'s view of the set with OpenGL, from the panorama the scene samples.
  void drawView(PipelineOutputs::PictureOutput& output, FrameWork& work, bool& cameraUploaded);
  void uploadPanorama();
  // The GPU times of the runs finished since the last call into gpuTimes_.
  void collectGpuTimes();

  render::ViewSettings views_;
  // The context first, so that it outlives the GL objects of the scene (and of the outputs' views,
  // which the pipeline destroys before its stages).
  std::unique_ptr<render::EglContext> gl_;
  std::unique_ptr<render::SurroundScene> scene_;
  render::GpuTimer gpuTimer_;  // borrowed by the outputs' views
  // The GPU's own time of each run of its steps so far (render/gpu_timer.hpp), read a set or two
  // after the run; none where the driver cannot time them.
  std::array<DurationHistogram, render::kGpuSteps> gpuTimes_{};
  const cv::Mat& panorama_;
  GpuPanorama gpu_;
  bool panoramaOnGpu_ = false;  // the scene samples gpu_'s panorama (the last set's)
  FixedViews fixed_;
  GuidelineMode guidelineMode_;
  std::optional<render::GuidelineLayer> guides_;  // none: guidelines off
  std::size_t splitCamera_;
  std::chrono::nanoseconds lastStreamTime_{0};
};

}  // namespace surroundd::daemon
