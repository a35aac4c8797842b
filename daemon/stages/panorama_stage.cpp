#include "daemon/stages/panorama_stage.hpp"

#include <algorithm>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>

#include <spdlog/spdlog.h>

#include "daemon/config/panorama_setup.hpp"
#include "processing/colour/camera_gains.hpp"
#include "processing/stitch/i420_picture.hpp"
#include "processing/stitch/view_lut.hpp"

namespace surroundd::daemon {

PanoramaStage::PanoramaStage(const Config& config, WorkPool& pool)
    : config_(config),
      pool_(pool),
      tables_(std::make_shared<PanoramaTables>(config, rigOf(config, pool), pool, pool)),
      corrected_(config.cameras.size()),
      stitched_(config.cameras.size()),
      dmabufs_(config.cameras.size()),
      // Black until a set needs it stitched: an output may be handed it before (at the run's end).
      panorama_(tables_->lut.size, CV_8UC3, cv::Scalar::all(0)) {}

PanoramaStage::~PanoramaStage() = default;

void PanoramaStage::remount(processing::Rig rig) {
  // One core: the other goes on with the sets. A build replaced by a later one finishes unread.
  std::packaged_task<std::shared_ptr<PanoramaTables>()> build(
      [this, rig = std::move(rig)]() mutable {
        WorkPool caller(1);
        return std::make_shared<PanoramaTables>(config_, std::move(rig), caller, pool_);
      });
  remount_ = build.get_future();
  builds_.emplace_back(std::move(build));
}

void PanoramaStage::takeRemountedTables() {
  if (!remount_.valid() ||
      remount_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    return;
  }
  try {
    tables_ = remount_.get();
    ++generation_;
    spdlog::info("panorama: the look-up table for the cameras' new mounts is in use");
  } catch (const std::exception& e) {
    spdlog::error(
        "panorama: the corrected mounts cannot make a panorama ({}); they stay as they "
        "were",
        e.what());
  }
}

const cv::Mat& PanoramaStage::blackFrame(std::size_t camera, PixelFormat format) {
  std::vector<cv::Mat>& frames = blackFrames_[static_cast<std::size_t>(format)];
  if (frames.empty()) {
    for (const auto& size : tables_->lut.cameraSizes) frames.push_back(blackPicture(format, size));
  }
  return frames[camera];
}

PixelFormat PanoramaStage::gatherFrames(FrameWork& work) {
  // The frames as their cameras gave them when they all hold one format (the kernels sample one
  // format per stitch); a rig that mixes formats is sampled in BGR, each frame converted.
  std::optional<PixelFormat> shared;
  for (std::size_t c = 0; c < work.set.cameraCount; ++c) {
    const capture::Frame* frame = work.set.frame(c);
    if (frame == nullptr) continue;
    if (shared && *shared != frame->format) {
      shared = PixelFormat::kBgr;
      break;
    }
    shared = frame->format;
  }
  const PixelFormat format = shared.value_or(PixelFormat::kBgr);
  for (std::size_t c = 0; c < work.set.cameraCount; ++c) {
    const capture::Frame* frame = work.set.frame(c);
    const cv::Mat* image = frame == nullptr              ? nullptr
                           : format == PixelFormat::kBgr ? work.bgr(c)
                                                         : &frame->image;
    // A faulty camera's picture would pull its neighbours' colours: correction goes without it.
    corrected_[c] = image != nullptr && work.faults[c] == nullptr ? *image : cv::Mat();
    stitched_[c] = image != nullptr ? *image : blackFrame(c, format);
    dmabufs_[c] = frame != nullptr && image == &frame->image ? frame->dmabuf : DmabufPlanes{};
  }
  return format;
}

void PanoramaStage::process(FrameWork& work, StageTimes& times) {
  takeRemountedTables();
  PanoramaTables& tables = *tables_;
  format_ = gatherFrames(work);
  const bool wanted = work.needed(Need::kPanorama);
  if (wanted) tables.stitcher.stitch(stitched_, format_, panorama_);
  times.lap(Stage::kStitch);
  if (tables.poisson) {
    tables.poisson->update(corrected_, format_);
    for (const auto& note : tables.poisson->notesOfLastUpdate()) {
      spdlog::warn("colour correction: {}", note);
    }
    if (wanted) tables.poisson->apply(panorama_);
  } else if (tables.gains) {
    tables.gains->update(corrected_, format_);
    for (const auto& note : tables.gains->notesOfLastUpdate()) {
      spdlog::warn("colour correction: {}", note);
    }
    if (wanted) tables.gains->apply(panorama_);
  }
  for (std::size_t c = 0; c < work.set.cameraCount && wanted; ++c) {
    if (work.faults[c] != nullptr) tables.ownership.markFaulty(panorama_, c);
  }
  if (wanted) work.panorama = &panorama_;
  times.lap(Stage::kCorrect);
}

PanoramaStage::ViewPicture::ViewPicture(const PanoramaTables& tables,
                                        const cv::Mat& panoramaPositions, WorkPool& compose,
                                        WorkPool& pool)
    : lut_(processing::composeViewLut(tables.lut, panoramaPositions, compose)),
      stitcher_(lut_, pool),
      ownership_(lut_) {
  if (tables.poisson) fieldSamples_ = tables.poisson->viewSamples(panoramaPositions);
}

std::future<std::unique_ptr<PanoramaStage::ViewPicture>> PanoramaStage::buildView(
    cv::Mat panoramaPositions) {
  // One core: the other goes on with the sets. The positions are this thread's alone from here.
  // The tables it is made from stay while it is made, also should a remount replace them here.
  std::packaged_task<std::unique_ptr<ViewPicture>()> build(
      [this, tables = std::shared_ptr<const PanoramaTables>(tables_), generation = generation_,
       positions = std::move(panoramaPositions)] {
        const auto start = std::chrono::steady_clock::now();
        WorkPool caller(1);
        auto view = std::make_unique<ViewPicture>(*tables, positions, caller, pool_);
        view->composedIn_ = std::chrono::steady_clock::now() - start;
        view->generation_ = generation;
        return view;
      });
  auto built = build.get_future();
  builds_.emplace_back(std::move(build));
  return built;
}

void PanoramaStage::gather(ViewPicture& view, cv::Mat& picture) {
  // The same frames as the panorama's.
  view.stitcher_.stitch(stitched_, format_, picture);
}

void PanoramaStage::correct(ViewPicture& view, const FrameWork& work, cv::Mat& picture,
                            cv::Mat* i420) {
  if (view.generation_ != generation_) {
    throw std::logic_error("a view made before the mounts were corrected: build it again");
  }
  const auto& poisson = tables_->poisson;
  const auto& gains = tables_->gains;
  if (poisson && !poisson->cameraGains().empty()) {
    processing::applyCameraGains(picture, view.lut_, poisson->cameraGains(), pool_);
  }
  const auto faults = std::span(work.faults).first(work.set.cameraCount);
  const bool anyFaulty = std::ranges::any_of(faults, [](const char* f) { return f != nullptr; });
  if (poisson && i420 != nullptr && !anyFaulty) {
    poisson->applyAt(view.fieldSamples_, picture, *i420);
    return;
  }
  if (poisson) {
    poisson->applyAt(view.fieldSamples_, picture);
  } else if (gains) {
    gains->apply(picture, view.lut_);
  }
  for (std::size_t c = 0; c < faults.size(); ++c) {
    if (faults[c] != nullptr) view.ownership_.markFaulty(picture, c);
  }
  if (i420 != nullptr) processing::bgrToI420(picture, *i420, pool_);
}

void PanoramaStage::report(PipelineReport& report) const {
  const auto& poisson = tables_->poisson;
  if (!poisson) return;
  ColourReport colour;
  colour.balanced = poisson->settings().balance;
  const auto name = [&](std::size_t camera) -> const std::string& {
    return tables_->rig.cameras.at(camera).name;
  };
  for (const auto& seam : poisson->seams()) {
    colour.seams.push_back({.name = name(seam.source) + "/" + name(seam.target),
                            .stepUncorrected = seam.stepUncorrected,
                            .stepCorrected = seam.stepCorrected,
                            .blocks = seam.blocks,
                            .clampedBlocks = seam.clampedBlocks,
                            .blocksLeftAsTheyWere = seam.droppedBlocks,
                            .leftAsItWas = seam.dropped});
  }
  for (const cv::Vec3f& gains : poisson->cameraGains()) {
    colour.balanceGains.push_back({gains[0], gains[1], gains[2]});
  }
  report.colour = std::move(colour);
}

}  // namespace surroundd::daemon
