#pragma once
// The surround views: the panorama textured onto the bowl / flat / 360 mesh around the car model
// (render/surround_scene.hpp), drawn with OpenGL ES into each surround output's own view. A view's
// read-back is collected while the next set is stitched, so each output gets its picture one set
// later (and the last one when the run ends).
//
// Views that do not move (top, 360, and orbit and split with a still eye; render.view_lut) are
// not drawn per set: the first time an output shows one, the renderer maps where each of its
// pixels samples the panorama and draws the car and background once; from then on the panorama
// stage gathers its picture from the camera frames (PanoramaStage::ViewPicture), the car and
// background are laid over it, and the split view's camera picture is scaled into its half. The
// output gets it in the same set. Kept for when the output shows that view again.
//
// Threads: the EGL context is made current on the thread that constructs the stage, which must be
// the one that runs it.

#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "daemon/config.hpp"
#include "daemon/pipeline_stage.hpp"
#include "daemon/stages/panorama_stage.hpp"
#include "render/egl_context.hpp"
#include "render/surround_scene.hpp"
#include "render/surround_view.hpp"
#include "vehicle/vehicle_signals.hpp"

namespace surroundd::daemon {

class SurroundStage final : public PipelineStage {
 public:
  // Opens the EGL context and builds the scene; `panorama` must outlive the stage. Throws
  // RenderError, or std::runtime_error naming the config for a mesh that cannot be built.
  SurroundStage(const Config& config, PanoramaStage& panorama);

  // A view for an output of `size` (even sides), first showing `view`.
  std::unique_ptr<render::SurroundView> makeView(cv::Size size, ViewKind view) const;

  // Maps each output's first view ahead of the first set when it does not move: composing its
  // view table takes tenths of a second, which belong to start-up, not to a set's frame time.
  void prepare(PipelineOutputs& outputs);

  // Whether this set needs the panorama: an output shows it, or a view drawn from it. Each output's
  // view that does not move is mapped here the first time it is shown (a view switched to; so that
  // one the renderer cannot map is drawn from the panorama too). For PanoramaStage::setWanted().
  bool needsPanorama(PipelineOutputs& outputs);

  void process(FrameWork& work, StageTimes& times) override;
  void finish(PipelineOutputs& outputs) override;
  // The view of the last set, drawn again for an output that writes it at the end.
  cv::Mat redraw(PipelineOutputs::PictureOutput& output);

  std::string description() const { return gl_.description(); }

  // The vehicle's signals as they are now: the guidelines follow its gear and steering (drawn
  // again only when they change by a tenth of a degree or more).
  void setVehicleSignals(const vehicle::VehicleSignals& signals);

 private:
  // Hands each view's pending picture (the previous set's) to its output.
  void deliver(PipelineOutputs& outputs, StageTimes* times);

  // A fixed view's picture, and the renderer's car and background to lay over it.
  struct FixedView {
    std::unique_ptr<PanoramaStage::ViewPicture> view;
    cv::Mat overlay;                       // 8-bit BGR, the renderer's picture of the view
    cv::Mat overlayMask;                   // CV_8U: where it shows no panorama
    cv::Mat picture;                       // the last drawn
    std::chrono::nanoseconds drawnAt{-1};  // the stream time of its set
    bool handOver = false;                 // drawn this set for its output
    cv::Mat guides;                        // the guidelines as the view shows them, on black
    cv::Mat guidesGrey;
    cv::Mat guidesMask;      // CV_8U: where they are
    int guidesVersion = -1;  // of SurroundStage::guidesVersion_
  };
  // Lays the guidelines over a fixed view's picture, drawing them again when they have changed.
  void layGuidelines(render::SurroundView& view, FixedView& fixed);
  // The output's fixed view, built the first time it shows it; null for a view that moves, with
  // render.view_lut off, or where the renderer cannot map views (said once).
  FixedView* fixedView(render::SurroundView& view);

  render::ViewSettings views_;
  // The context first, so that it outlives the GL objects of the scene (and of the outputs' views,
  // which the pipeline destroys before its stages).
  render::EglContext gl_;
  std::unique_ptr<render::SurroundScene> scene_;
  PanoramaStage& panoramaStage_;
  const cv::Mat& panorama_;
  bool viewLut_;
  GuidelineMode guidelineMode_;
  render::GuidelineSettings guide_;
  render::CarDimensions car_;
  std::vector<render::GuidelineVertex> guideVertices_;  // reserved at start: filled in place
  // What the guidelines show now (travel, steering in tenths of a degree); none: not shown.
  std::optional<std::pair<render::Travel, long>> guidesShown_;
  int guidesVersion_ = 0;
  bool panoramaSkipped_ = false;  // this set: needsPanorama() said no
  // Per output's view (its address; each lives as long as the pipeline) and the kind it shows.
  std::map<std::pair<const render::SurroundView*, ViewKind>, FixedView> fixedViews_;
  std::size_t splitCamera_ = 0;
  std::chrono::nanoseconds lastStreamTime_{0};
};

}  // namespace surroundd::daemon
