#pragma once
// What the pipeline and its outputs ask of the surround views' renderer — the surround stage
// (daemon/stages/surround_stage.hpp) — so that the pipeline names no stage: a view for each
// surround output, the tables of the views that do not move, a view drawn again for an output
// that writes the last picture at the end, the context an output shows views through, and the
// vehicle's signals the guidelines follow. Threads: the pipeline thread only.

#include <memory>

#include <opencv2/core.hpp>

#include "daemon/config/config.hpp"
#include "daemon/pipeline_outputs.hpp"
#include "render/egl_context.hpp"
#include "render/surround_view.hpp"
#include "vehicle/vehicle_signals.hpp"

namespace surroundd::daemon {

class SurroundViews {
 public:
  virtual ~SurroundViews() = default;
  SurroundViews() = default;
  SurroundViews(const SurroundViews&) = delete;
  SurroundViews& operator=(const SurroundViews&) = delete;

  // A view for an output of `size` (even sides), first showing `view`.
  virtual std::unique_ptr<render::SurroundView> makeView(cv::Size size, ViewKind view) = 0;
  // `waitForTables` (a replay as fast as possible, whose pictures are all to come the same way):
  // maps each output's first view that does not move and waits for its table, ahead of the first
  // set. Else (a paced or live rig) the renderer draws the first picture, and the tables are
  // started once it has gone out: the first picture sooner.
  virtual void prepare(PipelineOutputs& outputs, bool waitForTables) = 0;
  // The view of the last set, drawn again for an output that writes it at the end.
  virtual cv::Mat redraw(PipelineOutputs::PictureOutput& output) = 0;
  // The renderer's context, current on the pipeline's thread: for outputs that show views on the
  // GPU.
  virtual render::EglContext& context() = 0;
  // The vehicle's signals as they are now: the guidelines follow its gear and steering.
  virtual void setVehicleSignals(const vehicle::VehicleSignals& signals) = 0;
};

}  // namespace surroundd::daemon
