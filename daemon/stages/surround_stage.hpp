#pragma once
// The surround views: the panorama textured onto the bowl / flat / 360 mesh around the car model
// (render/surround_scene.hpp), drawn with OpenGL ES into each surround output's own view. A view's
// read-back is collected while the next set is stitched, so each output gets its picture one set
// later (and the last one when the run ends).
//
// Threads: the EGL context is made current on the thread that constructs the stage, which must be
// the one that runs it.

#include <chrono>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "daemon/config.hpp"
#include "daemon/pipeline_stage.hpp"
#include "daemon/stages/panorama_stage.hpp"
#include "render/egl_context.hpp"
#include "render/surround_scene.hpp"
#include "render/surround_view.hpp"

namespace surroundd::daemon {

class SurroundStage final : public PipelineStage {
 public:
  // Opens the EGL context and builds the scene; `panorama` must outlive the stage. Throws
  // RenderError, or std::runtime_error naming the config for a mesh that cannot be built.
  SurroundStage(const Config& config, const PanoramaStage& panorama);

  // A view for an output of `size` (even sides), first showing `view`.
  std::unique_ptr<render::SurroundView> makeView(cv::Size size, ViewKind view) const;

  void process(FrameWork& work, StageTimes& times) override;
  void finish(PipelineOutputs& outputs) override;
  // The view of the last set, drawn again for an output that writes it at the end.
  cv::Mat redraw(PipelineOutputs::PictureOutput& output);

  std::string description() const { return gl_.description(); }

 private:
  // Hands each view's pending picture (the previous set's) to its output.
  void deliver(PipelineOutputs& outputs, StageTimes* times);

  render::ViewSettings views_;
  // The context first, so that it outlives the GL objects of the scene (and of the outputs' views,
  // which the pipeline destroys before its stages).
  render::EglContext gl_;
  std::unique_ptr<render::SurroundScene> scene_;
  const cv::Mat& panorama_;
  std::size_t splitCamera_ = 0;
  std::chrono::nanoseconds lastStreamTime_{0};
};

}  // namespace surroundd::daemon
