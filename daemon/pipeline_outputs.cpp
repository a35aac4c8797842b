#include "daemon/pipeline_outputs.hpp"

#include <algorithm>
#include <utility>

#include <spdlog/spdlog.h>

#include "daemon/config/output_files.hpp"
#include "daemon/config/output_type.hpp"

namespace surroundd::daemon {
namespace {

// The config's output, writing where no earlier run's data is lost.
OutputConfig withUnusedPath(OutputConfig output) {
  output.family = output.path;
  if (auto path = unusedOutputPath(output); path != output.path) {
    spdlog::info("{} holds what an earlier run wrote: this run writes {}", output.path.string(),
                 path.string());
    output.path = std::move(path);
  }
  return output;
}

}  // namespace

PipelineOutputs::PipelineOutputs(double nominalFps, bool latestWins)
    : nominalFps_(nominalFps), latestWins_(latestWins) {}

void PipelineOutputs::addPicture(const OutputConfig& config, cv::Size size, const cv::Mat* picture,
                                 std::unique_ptr<render::SurroundView> view) {
  PictureOutput output;
  output.config = config;
  output.size = size;
  output.picture = picture;
  open(output);
  output.view = std::move(view);
  pictures_.push_back(std::move(output));
}

void PipelineOutputs::addRecording(const OutputConfig& config,
                                   const std::vector<RigCamera>& cameras) {
  const OutputConfig output = withUnusedPath(config);
  recordings_.push_back(
      outputTypeOf(output).openCameraFramesSink(output, {{}, nominalFps_, latestWins_, &cameras}));
}

bool PipelineOutputs::shows(OutputStream stream) const {
  return std::ranges::any_of(
      pictures_, [&](const PictureOutput& o) { return o.config.stream == stream && o.sink; });
}

bool PipelineOutputs::drawing() const {
  return std::ranges::any_of(
      pictures_, [](const PictureOutput& o) { return o.view && o.sink && o.view->pending(); });
}

void PipelineOutputs::drop(PictureOutput& output, const std::exception& error) {
  output.sink.reset();
  output.retryDelay =
      output.onTrialSince ? std::min(2 * output.retryDelay, kLastOutputRetry) : kFirstOutputRetry;
  output.onTrialSince.reset();
  output.nextRetry = Clock::now() + output.retryDelay;
  spdlog::error("output failed, dropping it: {}; trying it again in {} s", error.what(),
                output.retryDelay.count());
  ++failures_;
}

template <typename Show>
void PipelineOutputs::deliver(PictureOutput& output, std::chrono::nanoseconds streamTime,
                              Clock::time_point origin, std::optional<render::DrawnPicture> drawn,
                              Show&& show) {
  guarded(output, [&] {
    // The wall clock of the capture, for viewers that measure how late they show it.
    const auto captured =
        std::chrono::system_clock::now() -
        std::chrono::duration_cast<std::chrono::system_clock::duration>(Clock::now() - origin);
    std::forward<Show>(show)(render::PictureTime{streamTime, captured});
    const auto now = Clock::now();
    latency_.record(now - origin);
    if (!firstPictureAt_) firstPictureAt_ = now;
    if (drawn) timeSwitch(output, *drawn, now);
    if (output.onTrialSince && now - *output.onTrialSince >= kOutputTrial) {
      output.onTrialSince.reset();
      spdlog::info("output {} works again", output.openedAs);
    }
  });
}

void PipelineOutputs::handOver(PictureOutput& output, const cv::Mat& picture,
                               std::chrono::nanoseconds streamTime, Clock::time_point origin,
                               std::optional<render::DrawnPicture> drawn, const cv::Mat* asBgr) {
  deliver(output, streamTime, origin, drawn, [&](const render::PictureTime& time) {
    output.sink->consume(picture, time);
    output.latest = asBgr != nullptr ? *asBgr : picture;
  });
}

void PipelineOutputs::present(PictureOutput& output, std::chrono::nanoseconds streamTime,
                              Clock::time_point origin, const render::DrawnPicture& drawn) {
  deliver(output, streamTime, origin, drawn,
          [&](const render::PictureTime& time) { output.sink->present(*output.view, time); });
}

void PipelineOutputs::switchView(PictureOutput& output, ViewKind view) {
  output.view->setView(view);
  output.switchSettled = false;
  output.handedSinceSwitch = false;
  if (render::ViewPage* page = output.sink ? output.sink->page() : nullptr) {
    page->setActiveView(toString(view));
  }
}

void PipelineOutputs::timeSwitch(PictureOutput& output, const render::DrawnPicture& drawn,
                                 Clock::time_point now) {
  if (!viewSwitch_ || viewSwitch_->settled) return;
  output.handedSinceSwitch = true;
  // A picture drawn before the request (the renderer's, handed over one set later) shows none of
  // it, but its output is one to wait for.
  if (drawn.at < viewSwitch_->requestedAt) return;
  if (!viewSwitch_->first) viewSwitch_->first = now - viewSwitch_->requestedAt;
  if (!drawn.settled) return;
  output.switchSettled = true;
  const bool allSettled = std::ranges::all_of(pictures_, [](const PictureOutput& o) {
    return !o.view || !o.sink || o.switchSettled || !o.handedSinceSwitch;
  });
  if (!allSettled) return;
  viewSwitch_->settled = now - viewSwitch_->requestedAt;
  spdlog::info("view switch: {}", viewSwitchWithLimits(*viewSwitch()));
}

std::optional<ViewSwitchTime> PipelineOutputs::viewSwitch() const {
  if (!viewSwitch_ || !viewSwitch_->first) return std::nullopt;
  ViewSwitchTime time{*viewSwitch_->first, std::nullopt};
  if (viewSwitch_->settled) time.settled = *viewSwitch_->settled;
  return time;
}

void PipelineOutputs::record(const capture::FrameSet& set) {
  for (auto& recording : recordings_) {
    if (!recording) continue;
    try {
      recording->record(set);
    } catch (const std::exception& e) {
      spdlog::error("recording failed, dropping it: {}", e.what());
      ++failures_;
      recording.reset();
    }
  }
}

void PipelineOutputs::open(PictureOutput& output) {
  // Where an earlier run or the failed try left data, this one writes the next name.
  const OutputConfig run = withUnusedPath(output.config);
  output.sink = outputTypeOf(run).openPictureSink(run, {.pictureSize = output.size,
                                                        .nominalFps = nominalFps_,
                                                        .latestWins = latestWins_,
                                                        .renderer = renderer_});
}

void PipelineOutputs::retry(Clock::time_point now) {
  for (auto& output : pictures_) {
    if (output.sink || now < output.nextRetry) continue;
    try {
      open(output);
      output.onTrialSince = now;
      output.openedAs = output.sink->describe();
      spdlog::info("output {} opened again: it works again once it has taken pictures for {} s",
                   output.openedAs, kOutputTrial.count());
    } catch (const std::exception& e) {
      output.retryDelay = std::min(2 * output.retryDelay, kLastOutputRetry);
      output.nextRetry = now + output.retryDelay;
      spdlog::error("output still failing: {}; trying it again in {} s", e.what(),
                    output.retryDelay.count());
    }
  }
}

void PipelineOutputs::followPages(bool statusDue, const std::function<std::string()>& status) {
  std::string text;
  for (auto& output : pictures_) {
    render::ViewPage* page = output.sink ? output.sink->page() : nullptr;
    if (page == nullptr) continue;
    if (const auto name = page->takeViewRequest(); name && output.view) {
      if (const auto view = render::parseViewKind(*name)) {
        for (auto& other : pictures_) other.switchSettled = true;
        viewSwitch_ = ViewSwitch{Clock::now(), std::nullopt, std::nullopt};
        switchView(output, *view);
      }
    }
    if (statusDue) {
      if (text.empty()) text = status();
      page->setStatus(text);
    }
  }
}

void PipelineOutputs::setView(ViewKind view) {
  viewSwitch_ = ViewSwitch{Clock::now(), std::nullopt, std::nullopt};
  for (auto& output : pictures_) {
    if (output.view) switchView(output, view);
  }
}

void PipelineOutputs::finish(std::chrono::nanoseconds lastTime,
                             const std::function<cv::Mat(PictureOutput&)>& lastPicture,
                             std::vector<std::string>& written) {
  for (auto& output : pictures_) {
    guarded(output, [&] {
      output.sink->finish(lastPicture(output), lastTime);
      written.push_back(output.sink->describe());
    });
  }
  for (auto& recording : recordings_) {
    if (!recording) continue;
    try {
      recording->finish();
      written.push_back(recording->describe());
    } catch (const std::exception& e) {
      spdlog::error("recording failed to finish: {}", e.what());
      ++failures_;
    }
  }
}

bool PipelineOutputs::anyWorks() const {
  return std::ranges::any_of(pictures_,
                             [](const PictureOutput& o) { return o.sink && !o.onTrialSince; }) ||
         std::ranges::any_of(recordings_, [](const auto& r) { return r != nullptr; });
}

cv::Mat PipelineOutputs::latestPicture(const std::function<cv::Mat(PictureOutput&)>& readBack) {
  const auto shown = [](const PictureOutput& o) { return !o.latest.empty(); };
  const auto onGpu = [](const PictureOutput& o) { return o.sink && o.sink->presentsViews(); };
  const auto surround = std::ranges::find_if(
      pictures_, [&](const PictureOutput& o) { return o.view && (shown(o) || onGpu(o)); });
  if (surround != pictures_.end()) return shown(*surround) ? surround->latest : readBack(*surround);
  const auto any = std::ranges::find_if(pictures_, shown);
  return any != pictures_.end() ? any->latest : cv::Mat();
}

std::uint64_t PipelineOutputs::dropped() const {
  std::uint64_t dropped = 0;
  for (const auto& output : pictures_) dropped += output.sink ? output.sink->dropped() : 0;
  return dropped;
}

}  // namespace surroundd::daemon
