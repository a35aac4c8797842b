#pragma once
// The surround views that do not move (top, 360, and orbit and split with a still eye;
// render.view_lut), gathered from the camera frames through tables of their own rather than drawn
// per set. The first time an output shows one (on a paced or live rig, once the first picture has
// gone out), or as a switch to it begins, the renderer maps where each of its pixels samples the
// panorama and the panorama stage composes the view's table from that on a thread of its own,
// while the renderer draws the view as it draws those that move. Once made, each set's picture is
// gathered from the camera frames (PanoramaStage::ViewPicture), the renderer's car and background
// laid where it shows no panorama and the split view's camera picture scaled into its half, then
// it is corrected and the guidelines laid over it; for an output that encodes it, it is converted
// to I420 in the correction's pass (processing/stitch/i420_picture.hpp). Its output gets it in the
// same set. Kept for when the output shows that view again, until the panorama is remounted
// (PanoramaStage::generation()): then each is mapped and composed again.
//
// Not with the GPU backend: a GPU draws a fixed view faster than the CPU gathers it.
// Threads: the renderer's context's, which is the pipeline thread.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <future>
#include <map>
#include <memory>
#include <utility>

#include <opencv2/core.hpp>

#include "daemon/config/config.hpp"
#include "daemon/pipeline_outputs.hpp"
#include "daemon/pipeline_stage.hpp"
#include "daemon/stage_times.hpp"
#include "daemon/stages/panorama_stage.hpp"
#include "render/guideline_layer.hpp"
#include "render/surround_view.hpp"

namespace surroundd::daemon {

class FixedViews {
 public:
  // A fixed view's picture, and the renderer's car and background to lay over it.
  struct View {
    // None while its table is being made, or where that failed.
    std::unique_ptr<PanoramaStage::ViewPicture> picturer;
    // Its table being made, until taken into `picturer`; and how long OpenGL's part of that took.
    std::future<std::unique_ptr<PanoramaStage::ViewPicture>> building;
    std::chrono::duration<double> mappedIn{0};
    cv::Mat overlay;                       // 8-bit BGR, the renderer's picture of the view
    cv::Mat overlayMask;                   // CV_8U: where it shows no panorama
    cv::Mat picture;                       // the last drawn
    cv::Mat i420;                          // and in I420, for an output that takes that
    bool inI420 = false;                   // whether `i420` is the picture its output gets
    std::chrono::nanoseconds drawnAt{-1};  // the stream time of its set
    bool handOver = false;                 // drawn this set for its output
    render::GuidelineOverlay guides;
  };

  // `enabled`: render.view_lut, and the CPU stitching. `panorama` must outlive them.
  FixedViews(const Config& config, bool enabled, PanoramaStage& panorama);
  FixedViews(const FixedViews&) = delete;
  FixedViews& operator=(const FixedViews&) = delete;

  // The fixed view `output` shows now, ready to be gathered; its table started the first time it
  // is shown. None until made and the switch to it has ended; for a view that moves, a sink that
  // shows views on the GPU, or where the renderer cannot map views (said once).
  View* ready(PipelineOutputs::PictureOutput& output);
  // Whether `output` shows a fixed view now, taken into use already; starts or takes nothing.
  bool shown(const PipelineOutputs::PictureOutput& output) const;

  // `waitForTables`: starts the tables of every output's first view and waits for them (a replay
  // as fast as possible). Else none is started until firstPictureOut(): mapping a view and
  // composing its table take the cores that the first picture needs.
  void prepare(PipelineOutputs& outputs, bool waitForTables);
  void firstPictureOut() { tablesAfterFirstPicture_ = false; }

  // `output`'s picture of the set, into `view` (from ready()): gathered, the car laid, corrected
  // and guided (`guides`: none, or those shown); handed over by handOver() where `wanted`.
  void draw(View& view, PipelineOutputs::PictureOutput& output, FrameWork& work, StageTimes& times,
            const render::GuidelineLayer* guides, bool wanted);
  // Hands each picture draw() made this set for its output over.
  void handOver(FrameWork& work);
  // `output`'s picture of the set at `streamTime`, where a fixed view made it; else null.
  const cv::Mat* pictureOf(const PipelineOutputs::PictureOutput& output,
                           std::chrono::nanoseconds streamTime) const;

 private:
  // Maps the view onto the panorama (OpenGL, here), then has the panorama stage build its table.
  void start(render::SurroundView& view, View& fixed);

  bool enabled_;
  PanoramaStage& panorama_;
  std::size_t splitCamera_;
  bool tablesAfterFirstPicture_ = false;  // prepare() without waiting: no table started yet
  std::uint64_t generation_;              // of the panorama's tables the views were made from
  // Per output's view (its address; each lives as long as the pipeline) and the kind it shows.
  std::map<std::pair<const render::SurroundView*, ViewKind>, View> views_;
};

}  // namespace surroundd::daemon
