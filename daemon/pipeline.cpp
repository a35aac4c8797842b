#include "daemon/pipeline.hpp"

#include <algorithm>
#include <array>

#include <spdlog/spdlog.h>

#include "daemon/config/output_type.hpp"
#include "daemon/pipeline_ends.hpp"
#include "daemon/stage_list.hpp"

namespace surroundd::daemon {
namespace {

// Between checks of the stop flag while a camera has nothing to deliver. Live, the wait is short:
// the other cameras' frames must not wait behind a late one past the set's deadline; and so it is
// while a picture is being drawn, to hand it over once finished.
constexpr std::chrono::milliseconds kCameraWait{200};
constexpr std::chrono::milliseconds kLiveCameraWait{2};
constexpr std::chrono::seconds kProgressInterval{10};
constexpr std::chrono::seconds kPageStatusInterval{1};

double nominalFpsOf(const std::vector<std::unique_ptr<capture::CameraStream>>& cameras) {
  return 1e9 / static_cast<double>(cameras.front()->nominalPeriod().count());
}

}  // namespace

Pipeline::Pipeline(const Config& config, RunStart start)
    : runStart_(start),
      renderer_(config.shows(OutputStream::kSurround) ? openSurroundRenderer(config)
                                                      : decltype(renderer_)()),
      cameras_(openCameras(config)),
      synchronizer_(cameras_.size(),
                    std::chrono::duration_cast<capture::Timestamp>(
                        std::chrono::duration<double, std::milli>(config.capture.syncToleranceMs))),
      live_(std::ranges::any_of(config.cameras, [](const RigCamera& c) { return c.live(); })),
      latestWins_(config.capture.latestWins == CaptureConfig::LatestWins::kAlways ||
                  (config.capture.latestWins == CaptureConfig::LatestWins::kAuto && live_)),
      lateAfter_(std::chrono::duration_cast<capture::Timestamp>(
          std::chrono::duration<double, std::milli>(config.capture.lateAfterMs))),
      pool_(config.pipeline.threads),
      outputs_(nominalFpsOf(cameras_), latestWins_) {
  StageList list = buildStages(
      config,
      {.cameras = cameras_, .synchronizer = synchronizer_, .pool = pool_, .renderer = renderer_});
  stages_ = std::move(list.stages);
  views_ = list.views;
  mounts_ = list.mounts;
  if (views_ != nullptr) outputs_.setRenderer(&views_->context());
  openOutputs(config);
  if (views_ != nullptr) {
    views_->prepare(outputs_, config.capture.pacing == capture::Pacing::kAsFastAsPossible);
  }
}

std::optional<StreamPicture> Pipeline::streamPicture(OutputStream stream) const {
  for (const auto& stage : stages_) {
    if (auto picture = stage->streamPicture(stream)) return picture;
  }
  return std::nullopt;
}

void Pipeline::openOutputs(const Config& config) {
  // The surround views are drawn at the size the mosaic is composed at: the config's.
  const cv::Size viewSize = streamPicture(OutputStream::kMosaic).value().size;
  for (OutputConfig output : config.outputs) {
    if (outputTypeOf(output).input == OutputInput::kCameraFrames) {
      outputs_.addRecording(output, config.cameras);
      continue;
    }
    const ViewKind view = output.view.value_or(config.render.view);
    output.view = view;
    if (output.stream == OutputStream::kSurround) {
      outputs_.addPicture(output, viewSize, nullptr, views_->makeView(viewSize, view));
    } else {
      const StreamPicture picture = streamPicture(output.stream).value();
      outputs_.addPicture(output, picture.size, picture.picture, nullptr);
    }
  }
}

Pipeline::~Pipeline() = default;

void Pipeline::setVehicleSignals(const vehicle::VehicleSignals& signals) {
  if (views_ != nullptr) views_->setVehicleSignals(signals);
}

PipelineReport Pipeline::report() const {
  PipelineReport report;
  const auto now = Clock::now();
  report.elapsed = now - start_;
  if (firstSetAt_) {
    report.setSpan = std::max(now, lastSetAt_ + cameras_.front()->nominalPeriod()) - *firstSetAt_;
  }
  report.frameSets = frameSets_;
  report.staleDropped = staleDropped_;
  report.sync = synchronizer_.stats();
  for (const auto& camera : cameras_) {
    report.cameras.push_back(
        {.name = camera->name(), .stats = camera->stats(), .queued = camera->queued()});
  }
  report.stages = times_.histograms();
  report.latency = outputs_.latency();
  if (const auto first = outputs_.firstPictureAt()) report.startup = *first - runStart_.at;
  report.startupFrom = runStart_.from;
  report.viewSwitch = outputs_.viewSwitch();
  report.outputs = outputs_.count();
  report.failedOutputs = outputs_.failures();
  report.failedSets = failedSets_;
  report.outputDropped = outputs_.dropped();
  for (const auto& stage : stages_) stage->report(report);
  return report;
}

RunSummary Pipeline::run(const std::atomic<bool>& stop, PipelineObserver* observer) {
  RunSummary summary;
  for (auto& camera : cameras_) camera->start();
  start_ = Clock::now();
  auto nextProgress = start_ + kProgressInterval;
  while (!stop && !synchronizer_.finished()) {
    const auto since = Clock::now();
    fillNeeds(stop);
    times_.waited(Clock::now() - since);
    while (auto set = nextSet(stop)) {
      times_.beginSet();
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
    // No set to work on: what has been made meanwhile goes out now, not with the next set.
    for (const auto& stage : stages_) stage->idle(outputs_, times_);
    logFirstPicture();
    const auto now = Clock::now();
    outputs_.retry(now);
    const bool statusDue = now >= nextPageStatus_;
    if (statusDue) nextPageStatus_ = now + kPageStatusInterval;
    outputs_.followPages(statusDue, [this] { return statusJson(report()); });
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

void Pipeline::logFirstPicture() {
  const auto first = outputs_.firstPictureAt();
  if (firstPictureLogged_ || !first) return;
  firstPictureLogged_ = true;
  spdlog::info("first picture out {}", startupWithLimits(*first - runStart_.at, runStart_.from));
}

bool Pipeline::dropFailedSet(const std::exception& error) {
  ++failedSets_;
  ++failedInARow_;
  times_.dropSet();
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

void Pipeline::fillNeeds(const std::atomic<bool>& stop) {
  for (std::size_t c = 0; c < cameras_.size() && !stop; ++c) {
    if (!synchronizer_.needs(c)) continue;
    capture::FrameRef frame;
    // While a picture is being drawn, the waits are short too: it goes out once finished.
    const bool briefly = live_ || outputs_.drawing();
    switch (cameras_[c]->next(frame, briefly ? kLiveCameraWait : kCameraWait)) {
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

void Pipeline::process(const capture::FrameSet& set) {
  times_.skip();
  lastSetAt_ = Clock::now();
  if (!firstSetAt_) firstSetAt_ = lastSetAt_;
  if (!firstTimestamp_) firstTimestamp_ = set.timestamp;
  lastStreamTime_ = set.timestamp - *firstTimestamp_;
  FrameWork work{.set = set,
                 .bgrBuffers = bgrBuffers_,
                 .streamTime = lastStreamTime_,
                 .origin = captureTimeOf(set),
                 .outputs = outputs_};
  for (std::size_t s = 0; s < stages_.size(); ++s) {
    work.later = std::span(stages_).subspan(s + 1);
    stages_[s]->process(work, times_);
  }
  times_.endSet();
}

cv::Mat Pipeline::latestPicture() {
  return outputs_.latestPicture([&](PipelineOutputs::PictureOutput& output) {
    return firstTimestamp_ ? views_->redraw(output) : cv::Mat();
  });
}

void Pipeline::finish(RunSummary& summary) {
  for (auto& camera : cameras_) camera->stop();
  for (const auto& stage : stages_) stage->finish(outputs_);
  // Outputs that write the last picture at the end are given that of the last set.
  outputs_.finish(
      lastStreamTime_,
      [&](PipelineOutputs::PictureOutput& output) {
        // A view shown on the GPU keeps its last picture: none is read back for it.
        if (!firstTimestamp_ || (output.sink && output.sink->presentsViews())) return cv::Mat();
        return output.view ? views_->redraw(output) : *output.picture;
      },
      summary.outputs);
  summary.failedOutputs = outputs_.failures();
  summary.sync = synchronizer_.stats();
  summary.stageTime = times_.totals();
  summary.report = report();
  summary.renderer = summary.report.renderer;
  for (const auto& camera : cameras_) {
    summary.cameraNames.push_back(camera->name());
    summary.cameras.push_back(camera->stats());
  }
}

bool FrameWork::needed(Need what) const {
  return std::ranges::any_of(later, [&](const auto& stage) { return stage->needs(what, *this); });
}

const cv::Mat* FrameWork::bgr(std::size_t camera) {
  const capture::Frame* frame = set.frame(camera);
  if (frame == nullptr) return nullptr;
  if (frame->format == PixelFormat::kBgr) return &frame->image;
  if (converted[camera] == nullptr) {
    heldToBgr(frame->image, frame->format, bgrBuffers[camera]);
    converted[camera] = &bgrBuffers[camera];
  }
  return converted[camera];
}

}  // namespace surroundd::daemon
