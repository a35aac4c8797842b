#include "daemon/stages/panorama_stage.hpp"

#include <algorithm>
#include <optional>
#include <span>
#include <string>
#include <utility>

#include <spdlog/spdlog.h>

#include "daemon/config/panorama_setup.hpp"
#include "daemon/pipeline_ends.hpp"
#include "processing/colour/camera_gains.hpp"
#include "processing/stitch/i420_picture.hpp"
#include "processing/stitch/view_lut.hpp"

namespace surroundd::daemon {

PanoramaStage::PanoramaStage(const Config& config, WorkPool& pool)
    : pool_(pool),
      rig_(rigOf(config, pool)),
      lut_(obtainPanoramaLut(config, rig_, pool)),
      stitcher_(lut_, pool),
      ownership_(lut_),
      corrected_(config.cameras.size()),
      stitched_(config.cameras.size()),
      dmabufs_(config.cameras.size()),
      // Black until a set needs it stitched: an output may be handed it before (at the run's end).
      panorama_(lut_.size, CV_8UC3, cv::Scalar::all(0)) {
  setUpColourCorrection(config, pool);
}

void PanoramaStage::setUpColourCorrection(const Config& config, WorkPool& pool) {
  const processing::ColourCorrectionSettings& settings = config.colour.poisson;
  if (config.colour.method == ColourMethod::kGain) {
    gains_ = std::make_unique<processing::GainCompensation>(lut_, pool, settings.minGain,
                                                            settings.maxGain, cameraNames(config));
    spdlog::info("colour correction: global gain compensation");
  } else if (config.colour.method == ColourMethod::kPoisson) {
    poisson_ = std::make_unique<processing::PoissonColourCorrection>(rig_, panoramaSettings(config),
                                                                     lut_, settings, pool);
    for (const auto& note : poisson_->notes()) spdlog::warn("colour correction: {}", note);
    spdlog::info("colour correction: Poisson, {} region(s) at scale {:g}, solver {}",
                 poisson_->domain().regions.size(), settings.scale, poisson_->solverNames());
  }
}

const cv::Mat& PanoramaStage::blackFrame(std::size_t camera, PixelFormat format) {
  std::vector<cv::Mat>& frames = blackFrames_[static_cast<std::size_t>(format)];
  if (frames.empty()) {
    for (const auto& size : lut_.cameraSizes) frames.push_back(blackPicture(format, size));
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
  format_ = gatherFrames(work);
  const bool wanted = work.needed(Need::kPanorama);
  if (wanted) stitcher_.stitch(stitched_, format_, panorama_);
  times.lap(Stage::kStitch);
  if (poisson_) {
    poisson_->update(corrected_, format_);
    for (const auto& note : poisson_->notesOfLastUpdate()) {
      spdlog::warn("colour correction: {}", note);
    }
    if (wanted) poisson_->apply(panorama_);
  } else if (gains_) {
    gains_->update(corrected_, format_);
    for (const auto& note : gains_->notesOfLastUpdate()) {
      spdlog::warn("colour correction: {}", note);
    }
    if (wanted) gains_->apply(panorama_);
  }
  for (std::size_t c = 0; c < work.set.cameraCount && wanted; ++c) {
    if (work.faults[c] != nullptr) ownership_.markFaulty(panorama_, c);
  }
  if (wanted) work.panorama = &panorama_;
  times.lap(Stage::kCorrect);
}

PanoramaStage::ViewPicture::ViewPicture(const PanoramaStage& stage,
                                        const cv::Mat& panoramaPositions, WorkPool& pool)
    : lut_(processing::composeViewLut(stage.lut_, panoramaPositions, pool)),
      stitcher_(lut_, stage.pool_),
      ownership_(lut_) {
  if (stage.poisson_) fieldSamples_ = stage.poisson_->viewSamples(panoramaPositions);
}

std::future<std::unique_ptr<PanoramaStage::ViewPicture>> PanoramaStage::buildView(
    cv::Mat panoramaPositions) {
  // One core: the other goes on with the sets. The positions are this thread's alone from here.
  std::packaged_task<std::unique_ptr<ViewPicture>()> build(
      [this, positions = std::move(panoramaPositions)] {
        const auto start = std::chrono::steady_clock::now();
        WorkPool caller(1);
        auto view = std::make_unique<ViewPicture>(*this, positions, caller);
        view->composedIn_ = std::chrono::steady_clock::now() - start;
        return view;
      });
  auto built = build.get_future();
  viewBuilds_.emplace_back(std::move(build));
  return built;
}

void PanoramaStage::gather(ViewPicture& view, cv::Mat& picture) {
  // The same frames as the panorama's.
  view.stitcher_.stitch(stitched_, format_, picture);
}

void PanoramaStage::correct(ViewPicture& view, const FrameWork& work, cv::Mat& picture,
                            cv::Mat* i420) {
  if (poisson_ && !poisson_->cameraGains().empty()) {
    processing::applyCameraGains(picture, view.lut_, poisson_->cameraGains(), pool_);
  }
  const auto faults = std::span(work.faults).first(work.set.cameraCount);
  const bool anyFaulty = std::ranges::any_of(faults, [](const char* f) { return f != nullptr; });
  if (poisson_ && i420 != nullptr && !anyFaulty) {
    poisson_->applyAt(view.fieldSamples_, picture, *i420);
    return;
  }
  if (poisson_) {
    poisson_->applyAt(view.fieldSamples_, picture);
  } else if (gains_) {
    gains_->apply(picture, view.lut_);
  }
  for (std::size_t c = 0; c < faults.size(); ++c) {
    if (faults[c] != nullptr) view.ownership_.markFaulty(picture, c);
  }
  if (i420 != nullptr) processing::bgrToI420(picture, *i420, pool_);
}

void PanoramaStage::report(PipelineReport& report) const {
  if (!poisson_) return;
  ColourReport colour;
  colour.balanced = poisson_->settings().balance;
  const auto name = [&](std::size_t camera) -> const std::string& {
    return rig_.cameras.at(camera).name;
  };
  for (const auto& seam : poisson_->seams()) {
    colour.seams.push_back({.name = name(seam.source) + "/" + name(seam.target),
                            .stepUncorrected = seam.stepUncorrected,
                            .stepCorrected = seam.stepCorrected,
                            .blocks = seam.blocks,
                            .clampedBlocks = seam.clampedBlocks,
                            .blocksLeftAsTheyWere = seam.droppedBlocks,
                            .leftAsItWas = seam.dropped});
  }
  for (const cv::Vec3f& gains : poisson_->cameraGains()) {
    colour.balanceGains.push_back({gains[0], gains[1], gains[2]});
  }
  report.colour = std::move(colour);
}

}  // namespace surroundd::daemon
