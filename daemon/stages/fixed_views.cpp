#include "daemon/stages/fixed_views.hpp"

#include <limits>

#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "daemon/config/output_type.hpp"
#include "daemon/stages/surround_renderer.hpp"
#include "processing/stitch/i420_picture.hpp"
#include "render/render_error.hpp"

namespace surroundd::daemon {

FixedViews::FixedViews(const Config& config, bool enabled, PanoramaStage& panorama)
    : enabled_(enabled),
      panorama_(panorama),
      splitCamera_(splitCameraOf(config)),
      generation_(panorama.generation()) {}

FixedViews::View* FixedViews::ready(PipelineOutputs::PictureOutput& output) {
  render::SurroundView& view = *output.view;
  if (!enabled_ || output.sink->presentsViews() || !view.settlesStill()) return nullptr;
  if (generation_ != panorama_.generation()) {
    // Made through the old mounts; a build under way finishes unread.
    views_.clear();
    generation_ = panorama_.generation();
  }
  const ViewKind kind = view.view();
  const auto key = std::pair{static_cast<const render::SurroundView*>(&view), kind};
  const auto known = views_.find(key);
  if (known == views_.end()) {
    if (!tablesAfterFirstPicture_) start(view, views_[key]);
    return nullptr;
  }
  View& fixed = known->second;
  if (fixed.building.valid()) {
    if (fixed.building.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
      return nullptr;
    }
    try {
      fixed.picturer = fixed.building.get();
      // Drawn now, not with the map: each takes its own set's time.
      fixed.overlay = view.stillPicture(0);
      fixed.picture = fixed.overlay.clone();
      spdlog::info(
          "render: the {} view {}x{} is gathered from the camera frames through its own "
          "look-up table (made in {:.2f} s: {:.2f} s mapping it with OpenGL, {:.2f} s composing "
          "it beside the sets)",
          toString(kind), view.size().width, view.size().height,
          (fixed.mappedIn + fixed.picturer->composedIn()).count(), fixed.mappedIn.count(),
          fixed.picturer->composedIn().count());
    } catch (const std::exception& e) {
      fixed.picturer.reset();
      spdlog::warn("render: the {} view is drawn by OpenGL: {}", toString(kind), e.what());
    }
  }
  // Until a switch to it has ended, the renderer draws the way there.
  return fixed.picturer && !view.moves() ? &fixed : nullptr;
}

bool FixedViews::shown(const PipelineOutputs::PictureOutput& output) const {
  const render::SurroundView& view = *output.view;
  if (!enabled_ || output.sink->presentsViews() || view.moves() ||
      generation_ != panorama_.generation()) {
    return false;
  }
  const auto known = views_.find({&view, view.view()});
  return known != views_.end() && known->second.picturer;
}

void FixedViews::start(render::SurroundView& view, View& fixed) {
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
    fixed.building = panorama_.buildView(positions);
  } catch (const render::RenderError& e) {
    spdlog::warn("render: the {} view is drawn by OpenGL: {}", toString(view.view()), e.what());
  }
}

void FixedViews::prepare(PipelineOutputs& outputs, bool waitForTables) {
  if (!waitForTables) {
    tablesAfterFirstPicture_ = true;
    return;
  }
  const auto eachFirstView = [&] {
    for (auto& output : outputs.pictures()) {
      if (output.view && output.sink) (void)ready(output);
    }
  };
  eachFirstView();  // starts the tables
  for (auto& [key, fixed] : views_) {
    if (fixed.building.valid()) fixed.building.wait();
  }
  eachFirstView();  // takes them into use
}

void FixedViews::draw(View& view, PipelineOutputs::PictureOutput& output, FrameWork& work,
                      StageTimes& times, const render::GuidelineLayer* guides, bool wanted) {
  times.lap(Stage::kRender);  // the views drawn before this one
  // The car, the background and the split view's camera go where the view shows no panorama,
  // before the correction, which leaves those pixels as they are; the guidelines over the
  // corrected picture.
  panorama_.gather(*view.picturer, view.picture);
  view.overlay.copyTo(view.picture, view.overlayMask);
  // As the renderer samples it (bilinear, pixel centres at halves); a missing frame leaves the
  // last one shown.
  const auto area = output.view->cameraArea();
  if (const cv::Mat* camera = area ? work.bgr(splitCamera_) : nullptr; camera != nullptr) {
    cv::Mat into = view.picture(*area);
    cv::resize(*camera, into, area->size(), 0, 0, cv::INTER_LINEAR);
  }
  times.lap(Stage::kStitch);
  // An encoder's picture is made in I420 as it is corrected; with guidelines, after them.
  const bool guided = guides != nullptr && guides->shown();
  view.inI420 = output.sink->takesI420();
  panorama_.correct(*view.picturer, work, view.picture,
                    view.inI420 && !guided ? &view.i420 : nullptr);
  if (guided) {
    view.guides.layOver(*output.view, *guides, view.picture);
    if (view.inI420) processing::bgrToI420(view.picture, view.i420, panorama_.pool());
  }
  times.lap(Stage::kCorrect);
  view.drawnAt = work.streamTime;
  view.handOver = wanted;
}

void FixedViews::handOver(FrameWork& work) {
  for (auto& output : work.outputs.pictures()) {
    if (!output.view) continue;
    const auto fixed = views_.find({output.view.get(), output.view->view()});
    if (fixed == views_.end() || !fixed->second.handOver) continue;
    fixed->second.handOver = false;
    // Gathered in this set, with the view settled: a fixed view does not move.
    const View& drawn = fixed->second;
    work.outputs.handOver(output, drawn.inI420 ? drawn.i420 : drawn.picture, work.streamTime,
                          work.origin, render::DrawnPicture{PipelineOutputs::Clock::now(), true},
                          &drawn.picture);
  }
}

const cv::Mat* FixedViews::pictureOf(const PipelineOutputs::PictureOutput& output,
                                     std::chrono::nanoseconds streamTime) const {
  const auto fixed = views_.find({output.view.get(), output.view->view()});
  if (fixed == views_.end() || !fixed->second.picturer || fixed->second.drawnAt != streamTime) {
    return nullptr;
  }
  return &fixed->second.picture;
}

}  // namespace surroundd::daemon
