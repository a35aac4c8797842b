#include "daemon/pipeline.hpp"

#include <algorithm>
#include <array>

#include <spdlog/spdlog.h>

#include "daemon/output_files.hpp"
#include "daemon/output_type.hpp"
#include "daemon/panorama_setup.hpp"
#include "daemon/pipeline_ends.hpp"

namespace surroundd::daemon {
namespace {

// Between checks of the stop flag while a camera has nothing to deliver. Live, the wait is short:
// the other cameras' frames must not wait behind a late one past the set's deadline.
constexpr std::chrono::milliseconds kCameraWait{200};
constexpr std::chrono::milliseconds kLiveCameraWait{2};
constexpr std::chrono::seconds kProgressInterval{10};
constexpr std::chrono::seconds kPageStatusInterval{1};

}  // namespace

Pipeline::Pipeline(const Config& config)
    : cameras_(openCameras(config)),
      synchronizer_(cameras_.size(),
                    std::chrono::duration_cast<capture::Timestamp>(
                        std::chrono::duration<double, std::milli>(config.capture.syncToleranceMs))),
      live_(std::ranges::any_of(config.cameras, [](const RigCamera& c) { return c.live(); })),
      latestWins_(config.capture.latestWins == CaptureConfig::LatestWins::kAlways ||
                  (config.capture.latestWins == CaptureConfig::LatestWins::kAuto && live_)),
      lateAfter_(std::chrono::duration_cast<capture::Timestamp>(
          std::chrono::duration<double, std::milli>(config.capture.lateAfterMs))),
      health_(cameras_.size()),
      pool_(config.pipeline.threads),
      mosaic_(cv::Size(config.render.widthPx, config.render.heightPx), cameraNames(config)),
      canvas_(mosaic_.outputSize(), CV_8UC3, cv::Scalar::all(0)) {
  setUpHealthChecks(config, cameras_, health_);
  const auto configured = [&](OutputStream stream) {
    return std::ranges::any_of(config.outputs, [&](const auto& o) { return o.stream == stream; });
  };
  if (configured(OutputStream::kPanorama) || configured(OutputStream::kSurround)) {
    const processing::Rig rig = rigOf(config, pool_);
    lut_ = std::make_unique<processing::PanoramaLut>(obtainPanoramaLut(config, rig, pool_));
    stitcher_ = std::make_unique<processing::Stitcher>(*lut_, pool_);
    ownership_ = std::make_unique<processing::PanoramaOwnership>(*lut_);
    panorama_.create(lut_->size, CV_8UC3);
    for (const auto& size : lut_->cameraSizes) {
      blackFrames_.emplace_back(size, CV_8UC3, cv::Scalar::all(0));
    }
    frames_.resize(cameras_.size());
    stitchInputs_.resize(cameras_.size());
    setUpColourCorrection(config, rig);
  }
  if (configured(OutputStream::kSurround)) setUpSurround(config);
  const double nominalFps = 1e9 / static_cast<double>(cameras_.front()->nominalPeriod().count());
  for (OutputConfig output : config.outputs) {
    if (auto path = unusedOutputPath(output); path != output.path) {
      spdlog::info("{} holds what an earlier run wrote: this run writes {}", output.path.string(),
                   path.string());
      output.path = std::move(path);
    }
    const OutputType& type = outputTypeOf(output);
    if (type.input == OutputInput::kCameraFrames) {
      recorders_.push_back(
          type.openCameraFramesSink(output, {{}, nominalFps, latestWins_, &config.cameras}));
      continue;
    }
    Output out;
    out.stream = output.stream;
    out.config = output;
    out.size = output.stream == OutputStream::kPanorama ? lut_->size : mosaic_.outputSize();
    out.nominalFps = nominalFps;
    const ViewKind view = output.view.value_or(config.render.view);
    out.config.view = view;
    open(out);
    if (output.stream == OutputStream::kSurround) {
      out.view =
          std::make_unique<render::SurroundView>(*scene_, out.size, view, config.render.views);
    }
    outputs_.push_back(std::move(out));
  }
}

void Pipeline::setUpColourCorrection(const Config& config, const processing::Rig& rig) {
  if (config.colour.method == ColourMethod::kGain) {
    gains_ = std::make_unique<processing::GainCompensation>(
        *lut_, pool_, config.colour.poisson.minGain, config.colour.poisson.maxGain,
        cameraNames(config));
    spdlog::info("colour correction: global gain compensation");
  } else if (config.colour.method == ColourMethod::kPoisson) {
    const processing::ColourCorrectionSettings& settings = config.colour.poisson;
    poisson_ = std::make_unique<processing::PoissonColourCorrection>(rig, panoramaSettings(config),
                                                                     *lut_, settings, pool_);
    for (const auto& note : poisson_->notes()) spdlog::warn("colour correction: {}", note);
    spdlog::info("colour correction: Poisson, {} region(s) at scale {:g}, solver {}",
                 poisson_->domain().regions.size(), settings.scale, poisson_->solverNames());
  }
}

void Pipeline::setUpSurround(const Config& config) {
  gl_ = std::make_unique<render::EglContext>(config.render.platform);
  spdlog::info("render: {}", gl_->description());
  const processing::PanoramaSettings panorama = panoramaSettings(config);
  processing::SurroundMesh mesh;
  try {
    mesh = processing::buildSurroundMesh(meshSettings(config), panorama.geometry);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(fmt::format("{}: {}", config.file.string(), e.what()));
  }
  const auto names = cameraNames(config);
  const auto split = std::ranges::find(names, config.render.splitCamera);
  splitCamera_ = split == names.end() ? 0 : static_cast<std::size_t>(split - names.begin());
  scene_ = std::make_unique<render::SurroundScene>(mesh, panorama.geometry, config.render.car,
                                                   lut_->cameraSizes.at(splitCamera_));
  spdlog::info("render: {} mesh of {} triangles, split view shows '{}'",
               config.mesh.model == MeshModel::kBowl   ? "bowl"
               : config.mesh.model == MeshModel::kFlat ? "flat"
                                                       : "sphere360",
               mesh.indices.size() / 3, names[splitCamera_]);
}

const cv::Mat& Pipeline::imageOf(OutputStream stream) const {
  return stream == OutputStream::kPanorama ? panorama_ : canvas_;
}

Pipeline::~Pipeline() = default;

void Pipeline::setView(ViewKind view) {
  for (auto& output : outputs_) {
    if (!output.view) continue;
    output.view->setView(view);
    if (render::ViewPage* page = output.sink ? output.sink->page() : nullptr) {
      page->setActiveView(toString(view));
    }
  }
}

PipelineReport Pipeline::report() const {
  PipelineReport report;
  report.elapsed = Clock::now() - start_;
  report.frameSets = frameSets_;
  report.staleDropped = staleDropped_;
  report.sync = synchronizer_.stats();
  for (std::size_t c = 0; c < cameras_.size(); ++c) {
    report.cameras.push_back(
        {cameras_[c]->name(), health_.health(c), cameras_[c]->stats(), cameras_[c]->queued()});
  }
  report.stages = stageHistograms_;
  report.latency = latency_;
  report.outputs = outputs_.size() + recorders_.size();
  report.failedOutputs = failedSinks_;
  report.failedSets = failedSets_;
  for (const auto& output : outputs_)
    report.outputDropped += output.sink ? output.sink->dropped() : 0;
  if (gl_) report.renderer = gl_->description();
  return report;
}

cv::Mat Pipeline::latestPicture() const {
  const auto shown = [](const Output& o) { return !o.latest.empty(); };
  const auto surround =
      std::ranges::find_if(outputs_, [&](const Output& o) { return o.view && shown(o); });
  if (surround != outputs_.end()) return surround->latest;
  const auto any = std::ranges::find_if(outputs_, shown);
  return any != outputs_.end() ? any->latest : cv::Mat();
}

RunSummary Pipeline::run(const std::atomic<bool>& stop, PipelineObserver* observer) {
  RunSummary summary;
  for (auto& camera : cameras_) camera->start();
  start_ = Clock::now();
  auto nextProgress = start_ + kProgressInterval;
  while (!stop && !synchronizer_.finished()) {
    auto since = Clock::now();
    fillNeeds(stop);
    setStageTime_[static_cast<std::size_t>(Stage::kSync)] += Clock::now() - since;
    while (auto set = nextSet(stop)) {
      stageTime_[static_cast<std::size_t>(Stage::kSync)] +=
          setStageTime_[static_cast<std::size_t>(Stage::kSync)];
      setStagesRun_.set(static_cast<std::size_t>(Stage::kSync));
      try {
        if (observer != nullptr) observer->onFrameSet(*this, *set);
        process(*set);
        failedInARow_ = 0;
        ++frameSets_;
      } catch (const std::exception& e) {
        if (dropFailedSet(e)) {
          summary.rebuild = true;
          break;
        }
      }
    }
    if (summary.rebuild) break;
    const auto now = Clock::now();
    retryOutputs(now);
    followPages(now);
    if (now >= nextProgress) {
      nextProgress += kProgressInterval;
      spdlog::info("{} frame sets, {}", frameSets_, statusLine(report()));
    }
    if (observer != nullptr) observer->onLoop(*this, now, frameSets_);
  }
  if (observer != nullptr) observer->onStopping();
  if (stop) spdlog::info("stop requested: finalizing outputs");
  finish(summary);
  summary.frameSets = frameSets_;
  summary.failedSets = failedSets_;
  summary.wallTime = Clock::now() - start_;
  return summary;
}

bool Pipeline::dropFailedSet(const std::exception& error) {
  ++failedSets_;
  ++failedInARow_;
  setStageTime_.fill(std::chrono::nanoseconds(0));
  setStagesRun_.reset();
  const auto now = Clock::now();
  if (now - lastFailureLog_ >= std::chrono::seconds(1)) {
    spdlog::error("frame set dropped: {}{}", error.what(),
                  unloggedFailures_ == 0
                      ? std::string()
                      : fmt::format(" ({} more since the last such message)", unloggedFailures_));
    lastFailureLog_ = now;
    unloggedFailures_ = 0;
  } else {
    ++unloggedFailures_;
  }
  if (failedInARow_ < kRebuildAfterFailures) return false;
  spdlog::error("{} frame sets failed in a row: the pipeline is rebuilt", failedInARow_);
  return true;
}

std::optional<capture::FrameSet> Pipeline::nextSet(const std::atomic<bool>& stop) {
  auto set = synchronizer_.pop();
  const auto newerWaiting = [this] {
    return std::ranges::all_of(cameras_, [](const auto& camera) { return camera->queued() > 0; });
  };
  while (latestWins_ && set && newerWaiting() && !stop) {
    ++staleDropped_;
    set.reset();  // its frames go back to their pools
    fillNeeds(stop);
    set = synchronizer_.pop();
  }
  // Live timestamps are CLOCK_MONOTONIC, which is steady_clock here.
  if (!set && live_) set = synchronizer_.popLate(Clock::now().time_since_epoch(), lateAfter_);
  return set;
}

void Pipeline::timed(Stage stage, Clock::time_point& since) {
  const auto now = Clock::now();
  const auto index = static_cast<std::size_t>(stage);
  stageTime_[index] += now - since;
  setStageTime_[index] += now - since;
  setStagesRun_.set(index);
  since = now;
}

void Pipeline::recordStages() {
  for (std::size_t s = 0; s < kStageCount; ++s) {
    if (setStagesRun_.test(s)) stageHistograms_[s].record(setStageTime_[s]);
  }
  setStageTime_.fill(std::chrono::nanoseconds(0));
  setStagesRun_.reset();
}

Pipeline::Clock::time_point Pipeline::captureTimeOf(const capture::FrameSet& set) const {
  auto oldest = Clock::time_point::max();
  for (std::size_t c = 0; c < set.cameraCount; ++c) {
    const capture::Frame* frame = set.frame(c);
    if (frame == nullptr) continue;
    // A live camera's timestamp is its driver's capture time on CLOCK_MONOTONIC; a replayed
    // frame's "capture" is when its decoder handed it over.
    oldest = std::min(oldest, live_ ? Clock::time_point(frame->timestamp) : frame->arrival);
  }
  return oldest;
}

void Pipeline::handOver(Output& output, const cv::Mat& picture, std::chrono::nanoseconds streamTime,
                        Clock::time_point origin) {
  guarded(output, [&] {
    output.sink->consume(picture, streamTime);
    output.latest = picture;
    latency_.record(Clock::now() - origin);
  });
}

template <typename Step>
void Pipeline::guarded(Output& output, Step&& step) {
  if (!output.sink) return;
  try {
    step();
  } catch (const std::exception& e) {
    output.sink.reset();
    output.retryDelay = kFirstOutputRetry;
    output.nextRetry = Clock::now() + output.retryDelay;
    spdlog::error("output failed, dropping it: {}; trying it again in {} s", e.what(),
                  output.retryDelay.count());
    ++failedSinks_;
  }
}

void Pipeline::open(Output& output) {
  // Where the failed try left data, this one writes the next name.
  output.config.path = unusedOutputPath(output.config);
  output.sink = outputTypeOf(output.config)
                    .openPictureSink(output.config, {output.size, output.nominalFps, latestWins_});
}

void Pipeline::retryOutputs(Clock::time_point now) {
  for (auto& output : outputs_) {
    if (output.sink || now < output.nextRetry) continue;
    try {
      open(output);
      spdlog::info("output {} works again", output.sink->describe());
    } catch (const std::exception& e) {
      output.retryDelay = std::min(2 * output.retryDelay, kLastOutputRetry);
      output.nextRetry = now + output.retryDelay;
      spdlog::error("output still failing: {}; trying it again in {} s", e.what(),
                    output.retryDelay.count());
    }
  }
}

bool Pipeline::outputsWork() const {
  return std::ranges::any_of(outputs_, [](const Output& o) { return o.sink != nullptr; }) ||
         std::ranges::any_of(recorders_, [](const auto& r) { return r != nullptr; });
}

void Pipeline::fillNeeds(const std::atomic<bool>& stop) {
  for (std::size_t c = 0; c < cameras_.size() && !stop; ++c) {
    if (!synchronizer_.needs(c)) continue;
    capture::FrameRef frame;
    switch (cameras_[c]->next(frame, live_ ? kLiveCameraWait : kCameraWait)) {
      case capture::CameraStream::Next::kFrame:
        synchronizer_.offer(c, std::move(frame));
        break;
      case capture::CameraStream::Next::kEnded:
        synchronizer_.end(c);
        break;
      case capture::CameraStream::Next::kTimeout:
        break;
    }
  }
}

bool Pipeline::shows(OutputStream stream) const {
  return std::ranges::any_of(outputs_,
                             [&](const Output& o) { return o.stream == stream && o.sink; });
}

void Pipeline::process(const capture::FrameSet& set) {
  auto since = Clock::now();
  const Clock::time_point origin = captureTimeOf(set);
  if (!firstTimestamp_) firstTimestamp_ = set.timestamp;
  lastStreamTime_ = set.timestamp - *firstTimestamp_;
  followHealth(set);
  for (auto& recorder : recorders_) {
    if (!recorder) continue;
    try {
      recorder->record(set);
    } catch (const std::exception& e) {
      spdlog::error("recording failed, dropping it: {}", e.what());
      ++failedSinks_;
      recorder.reset();
    }
  }
  std::array<const cv::Mat*, kMaxCameras> images{};
  for (std::size_t c = 0; c < set.cameraCount; ++c) {
    images[c] = set.frame(c) != nullptr ? &set.frame(c)->image : nullptr;
  }
  // Every set's mosaic, even when no sink wants this frame: it may be the last one, which a
  // snapshot asked for after the end is given. (Surround views are rendered again at the end.)
  if (shows(OutputStream::kMosaic)) {
    mosaic_.compose(std::span(images.data(), set.cameraCount), canvas_,
                    std::span(faults_.data(), set.cameraCount));
    timed(Stage::kMosaic, since);
  }
  // The panorama is made for every set, wanted or not: colour correction follows it over time.
  if (stitcher_) {
    for (std::size_t c = 0; c < set.cameraCount; ++c) {
      // A faulty camera's picture would pull its neighbours' colours: correction goes without it.
      frames_[c] = images[c] != nullptr && faults_[c] == nullptr ? *images[c] : cv::Mat();
      stitchInputs_[c] = images[c] != nullptr ? *images[c] : blackFrames_[c];
    }
    stitcher_->stitch(stitchInputs_, panorama_);
    timed(Stage::kStitch, since);
    if (poisson_) {
      poisson_->update(frames_);
      for (const auto& note : poisson_->notesOfLastUpdate()) {
        spdlog::warn("colour correction: {}", note);
      }
      poisson_->apply(panorama_);
    } else if (gains_) {
      gains_->update(frames_);
      for (const auto& note : gains_->notesOfLastUpdate()) {
        spdlog::warn("colour correction: {}", note);
      }
      gains_->apply(panorama_);
    }
    for (std::size_t c = 0; c < set.cameraCount; ++c) {
      if (faults_[c] != nullptr) ownership_->markFaulty(panorama_, c);
    }
    timed(Stage::kCorrect, since);
  }
  deliverSurround();
  renderSurround(set, origin);
  since = Clock::now();
  for (auto& output : outputs_) {
    if (output.view || !output.sink || !output.sink->wantsFrame(lastStreamTime_)) continue;
    handOver(output, imageOf(output.stream), lastStreamTime_, origin);
  }
  timed(Stage::kOutput, since);
  recordStages();
}

void Pipeline::followHealth(const capture::FrameSet& set) {
  for (const capture::HealthChange& change : health_.observe(set, synchronizer_.stats())) {
    const auto& name = cameras_[change.camera]->name();
    const double at = std::chrono::duration<double>(lastStreamTime_).count();
    if (change.to == capture::CameraHealth::kOk) {
      spdlog::info("camera '{}': back to normal at {:.3f} s (was {})", name, at,
                   capture::toString(change.from));
      faults_[change.camera] = nullptr;
    } else {
      spdlog::warn("camera '{}': {} at {:.3f} s; its part of the view is marked", name,
                   capture::toString(change.to), at);
      faults_[change.camera] = capture::toString(change.to);
    }
    healthChanges_.push_back(change);
    healthChanges_.back().at = lastStreamTime_;
  }
}

void Pipeline::followPages(Clock::time_point now) {
  const bool statusDue = now >= nextPageStatus_;
  if (statusDue) nextPageStatus_ = now + kPageStatusInterval;
  std::string status;
  for (auto& output : outputs_) {
    render::ViewPage* page = output.sink ? output.sink->page() : nullptr;
    if (page == nullptr) continue;
    if (const auto name = page->takeViewRequest(); name && output.view) {
      if (const auto view = render::parseViewKind(*name)) output.view->setView(*view);
    }
    if (statusDue) {
      if (status.empty()) status = statusJson(report());
      page->setStatus(status);
    }
  }
}

void Pipeline::renderSurround(const capture::FrameSet& set, Clock::time_point origin) {
  if (!scene_) return;
  const std::chrono::nanoseconds streamTime = lastStreamTime_;
  auto since = Clock::now();
  bool panoramaUploaded = false;
  bool cameraUploaded = false;
  for (auto& output : outputs_) {
    if (!output.view || !output.sink || !output.sink->wantsFrame(streamTime)) continue;
    guarded(output, [&] {
      if (!panoramaUploaded) {
        scene_->uploadPanorama(panorama_);
        panoramaUploaded = true;
      }
      const capture::Frame* camera = set.frame(splitCamera_);
      if (output.view->view() == ViewKind::kSplit && !cameraUploaded && camera != nullptr) {
        scene_->uploadCamera(camera->image);
        cameraUploaded = true;
      }
      output.view->draw(std::chrono::duration<double>(streamTime).count());
      output.pendingTime = streamTime;
      output.pendingOrigin = origin;
    });
  }
  timed(Stage::kRender, since);
}

void Pipeline::deliverSurround() {
  for (auto& output : outputs_) {
    if (!output.view || !output.view->pending()) continue;
    auto since = Clock::now();
    cv::Mat picture;
    guarded(output, [&] { picture = output.view->collect(); });
    timed(Stage::kReadBack, since);
    if (!picture.empty()) handOver(output, picture, output.pendingTime, output.pendingOrigin);
    timed(Stage::kOutput, since);
  }
}

void Pipeline::finish(RunSummary& summary) {
  for (auto& camera : cameras_) camera->stop();
  deliverSurround();
  bool panoramaUploaded = false;
  for (auto& output : outputs_) {
    guarded(output, [&] {
      cv::Mat last;  // the picture of the last frame set, for sinks that write it at the end
      if (firstTimestamp_ && output.view) {
        if (!panoramaUploaded) scene_->uploadPanorama(panorama_);
        panoramaUploaded = true;
        output.view->draw(std::chrono::duration<double>(lastStreamTime_).count());
        last = output.view->collect();
      } else if (firstTimestamp_) {
        last = imageOf(output.stream);
      }
      output.sink->finish(last, lastStreamTime_);
      summary.outputs.push_back(output.sink->describe());
    });
  }
  for (auto& recorder : recorders_) {
    if (!recorder) continue;
    try {
      recorder->finish();
      summary.outputs.push_back(recorder->describe());
    } catch (const std::exception& e) {
      spdlog::error("recording failed to finish: {}", e.what());
      ++failedSinks_;
    }
  }
  summary.failedOutputs = failedSinks_;
  summary.sync = synchronizer_.stats();
  summary.stageTime = stageTime_;
  summary.healthChanges = healthChanges_;
  if (gl_) summary.renderer = gl_->description();
  summary.report = report();
  for (const auto& camera : cameras_) {
    summary.cameraNames.push_back(camera->name());
    summary.cameras.push_back(camera->stats());
  }
}

}  // namespace surroundd::daemon
