#pragma once
// The pipeline's outputs, opened through their types' factories (output_type.hpp): those that
// take a picture per frame set (a stream's picture, or a surround view rendered for the output)
// and those that record the camera frames. One output's failure never stops the others: it is
// logged and the output dropped, then opened again after kFirstOutputRetry, then after twice as
// long each time, up to kLastOutputRetry (a disk with room again, a display plugged back in). An
// output opened again works again only once it has taken pictures for kOutputTrial without
// failing: until then it counts as failed (anyWorks(), and so the service's watchdog), and a
// failure keeps the retries' growing delay. An output opened on a full disk fails at its first
// writes: it did look healthy, and was opened every few seconds, while it recorded nothing.
//
// Error policy: adding an output throws what its factory throws (at start-up, naming the output);
// after that nothing here throws. Pipeline thread only.

#include <chrono>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "capture/frame_set.hpp"
#include "daemon/config/camera_frames_sink.hpp"
#include "daemon/config/config.hpp"
#include "daemon/duration_histogram.hpp"
#include "daemon/pipeline_report.hpp"
#include "render/egl_context.hpp"
#include "render/outputs/frame_sink.hpp"
#include "render/surround_view.hpp"

namespace surroundd::daemon {

class PipelineOutputs {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr std::chrono::seconds kFirstOutputRetry{1};
  static constexpr std::chrono::seconds kLastOutputRetry{60};
  static constexpr std::chrono::seconds kOutputTrial{2};

  // An output of pictures: a stream's picture, made by a stage, or a surround view of its own.
  struct PictureOutput {
    OutputConfig config;  // as configured: each opening writes the next unused name of its path
    cv::Size size;
    const cv::Mat* picture = nullptr;            // the stream's picture; null for a surround view
    std::unique_ptr<render::SurroundView> view;  // surround outputs
    std::unique_ptr<render::FrameSink> sink;     // null while it has failed
    Clock::time_point nextRetry{};               // when failed: when it is opened again
    std::chrono::seconds retryDelay{0};
    std::optional<Clock::time_point> onTrialSince;  // opened again, not yet working again
    // What the sink said it was when opened again: once it takes pictures, a queued sink's
    // describe() belongs to its worker, so the "works again" line names it by this.
    std::string openedAs;
    std::chrono::nanoseconds pendingTime{0};  // stream time of the view's pending picture
    Clock::time_point pendingOrigin{};        // capture time of the pending picture's set
    cv::Mat latest;                           // header over the picture last handed over, BGR
    // The current switch of view: whether the output shows it settled (or was spared it), and
    // whether it has had any picture since (an output that takes none, a snapshot after its
    // time, does not hold the switch's end back).
    bool switchSettled = true;
    bool handedSinceSwitch = false;
  };

  // `nominalFps`: the cameras' frame rate; `latestWins`: live, queues drop their oldest picture.
  PipelineOutputs(double nominalFps, bool latestWins);

  // Opens an output of `picture`'s stream (its size), or of `view` (picture null).
  void addPicture(const OutputConfig& config, cv::Size size, const cv::Mat* picture,
                  std::unique_ptr<render::SurroundView> view);
  // Opens a recording of `cameras`' frames.
  void addRecording(const OutputConfig& config, const std::vector<RigCamera>& cameras);

  std::vector<PictureOutput>& pictures() { return pictures_; }
  const std::vector<PictureOutput>& pictures() const { return pictures_; }
  // Whether a working output shows `stream`.
  bool shows(OutputStream stream) const;
  // Whether a working output's surround view has a picture drawn and not yet handed over.
  bool drawing() const;

  // Runs `step` on the output (if it works); an exception drops the output with a logged error.
  template <typename Step>
  void guarded(PictureOutput& output, Step&& step) {
    if (!output.sink) return;
    try {
      step();
    } catch (const std::exception& e) {
      drop(output, e);
    }
  }
  // Hands `picture` of the set captured at `origin` to the output (guarded), timing the latency;
  // a surround view's picture says when it was drawn, timing a switch of view. An I420 picture
  // (render/outputs/frame_sink.hpp) comes with the BGR one it was made from, `asBgr`, to be the
  // latest picture.
  void handOver(PictureOutput& output, const cv::Mat& picture, std::chrono::nanoseconds streamTime,
                Clock::time_point origin, std::optional<render::DrawnPicture> drawn = std::nullopt,
                const cv::Mat* asBgr = nullptr);
  // As handOver(), for an output whose sink shows its view as drawn, on the GPU
  // (FrameSink::presentsViews()): no picture, none read back.
  void present(PictureOutput& output, std::chrono::nanoseconds streamTime, Clock::time_point origin,
               const render::DrawnPicture& drawn);
  // The surround views' renderer, for the outputs opened from now on (OutputContext::renderer).
  void setRenderer(render::EglContext* renderer) { renderer_ = renderer; }
  // Each recording's copy of the set.
  void record(const capture::FrameSet& set);
  // Opens again the failed outputs whose retry is due.
  void retry(Clock::time_point now);
  // Outputs with a page (FrameSink::page()): switches the views they ask for; gives them
  // `status()` when `statusDue`.
  void followPages(bool statusDue, const std::function<std::string()>& status);
  // Every surround output shows `view` from the next frame set on.
  void setView(ViewKind view);
  // Finalizes every output; each picture output is given `lastPicture(output)`. Adds what each
  // wrote to `written`.
  void finish(std::chrono::nanoseconds lastTime,
              const std::function<cv::Mat(PictureOutput&)>& lastPicture,
              std::vector<std::string>& written);

  // Whether any output works: with none, the run records nothing (a full disk).
  bool anyWorks() const;
  // The newest picture handed to the first output that shows one (a surround view if any), in
  // BGR; a header over the pipeline's buffer, valid until the next frame set. Empty before. A
  // surround view shown on the GPU (FrameSink::presentsViews()) has none: `readBack(output)`
  // gives it.
  cv::Mat latestPicture(const std::function<cv::Mat(PictureOutput&)>& readBack);
  std::size_t count() const { return pictures_.size() + recordings_.size(); }
  std::uint64_t failures() const { return failures_; }
  std::uint64_t dropped() const;  // pictures outputs dropped because they fell behind
  const DurationHistogram& latency() const { return latency_; }
  // When the first picture was handed to an output; empty before.
  std::optional<Clock::time_point> firstPictureAt() const { return firstPictureAt_; }
  // The last switch of view's times; empty before its first picture.
  std::optional<ViewSwitchTime> viewSwitch() const;

 private:
  void open(PictureOutput& output);
  // Has `show` give the output the set's picture (guarded), then times it as handOver() says.
  template <typename Show>
  void deliver(PictureOutput& output, std::chrono::nanoseconds streamTime, Clock::time_point origin,
               std::optional<render::DrawnPicture> drawn, Show&& show);
  void drop(PictureOutput& output, const std::exception& error);
  // Switches `output`'s view as part of the switch requested now.
  void switchView(PictureOutput& output, ViewKind view);
  void timeSwitch(PictureOutput& output, const render::DrawnPicture& drawn, Clock::time_point now);

  struct ViewSwitch {
    Clock::time_point requestedAt;
    std::optional<Clock::duration> first;
    std::optional<Clock::duration> settled;
  };

  double nominalFps_;
  bool latestWins_;
  render::EglContext* renderer_ = nullptr;
  std::vector<PictureOutput> pictures_;
  std::vector<std::unique_ptr<CameraFramesSink>> recordings_;  // null once failed
  std::uint64_t failures_ = 0;
  DurationHistogram latency_;  // a set's capture to its picture handed to an output
  std::optional<Clock::time_point> firstPictureAt_;
  std::optional<ViewSwitch> viewSwitch_;
};

}  // namespace surroundd::daemon
