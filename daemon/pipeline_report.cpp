#include "daemon/pipeline_report.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "daemon/compliance_limits.hpp"
#include "processing/calibration/mount_refinement.hpp"

namespace surroundd::daemon {
namespace {

// ", mount would turn yaw +1.8°, pitch -0.4°, roll +0.2° (±0.05°)"; a fault says so.
std::string mountText(const MountSuggestion& mount) {
  return fmt::format(
      "{} yaw {:+.1f}°, pitch {:+.1f}°, roll {:+.1f}° (±{:.2f}°){}",
      mount.fault ? ", mount has turned" : ", mount would turn", mount.changeDeg.yawDeg,
      mount.changeDeg.pitchDeg, mount.changeDeg.rollDeg, mount.sigmaDeg,
      mount.fault ? fmt::format(": past the {:g}° a correction may make, check its mount",
                                processing::MountRefinementResult::kLargestTurnDeg)
                  : "");
}

// The drift watch's lines: each seam's figure, and the mount refinement's work.
std::string watchLines(const PipelineReport& report) {
  std::string out;
  for (const auto& seam : report.seams) {
    fmt::format_to(std::back_inserter(out), "seam {}: {}{}\n", seam.name,
                   seam.shiftCm ? fmt::format("ground {:.1f} cm apart at {:.1f} m (response "
                                              "{:.2f}){}",
                                              *seam.shiftCm, seam.distanceM, seam.response,
                                              seam.misaligned ? ", misaligned" : "")
                                : std::string("not measured yet"),
                   seam.suggestedCm
                       ? fmt::format("; {:.1f} cm with the mounts suggested", *seam.suggestedCm)
                       : std::string());
  }
  if (report.mountWatch) {
    fmt::format_to(std::back_inserter(out),
                   "mount refinement: {} sets compared, {} comparisons in the last solution, "
                   "{:.1f} s of CPU{}\n",
                   report.mountWatch->setsCompared, report.mountWatch->comparisons,
                   report.mountWatch->cpuSeconds,
                   report.mountWatch->applying
                       ? fmt::format("; corrections applied {}, taken back {}{}",
                                     report.mountWatch->applied, report.mountWatch->reverted,
                                     report.mountWatch->checking ? " (the last being checked)" : "")
                       : std::string());
  }
  return out;
}

// The colour correction's lines: what the balance does to each camera, and each seam's step.
std::string colourLines(const PipelineReport& report) {
  if (!report.colour) return {};
  const ColourReport& colour = *report.colour;
  std::string out = colour.balanced ? "colour: poisson after the balance" : "colour: poisson";
  for (std::size_t c = 0; c < colour.balanceGains.size() && c < report.cameras.size(); ++c) {
    const auto& gains = colour.balanceGains[c];
    fmt::format_to(std::back_inserter(out), "{} {} x{:.2f} {:.2f} {:.2f} (B G R)",
                   c == 0 ? ";" : ",", report.cameras[c].name, gains[0], gains[1], gains[2]);
  }
  out += '\n';
  for (const auto& seam : colour.seams) {
    fmt::format_to(std::back_inserter(out),
                   "colour seam {}: step {:.1f} -> {:.1f} levels, {} of {} blocks clamped",
                   seam.name, seam.stepUncorrected, seam.stepCorrected, seam.clampedBlocks,
                   seam.blocks);
    if (seam.leftAsItWas) {
      out += "; left as it was (correcting it made it worse)";
    } else if (seam.blocksLeftAsTheyWere > 0) {
      fmt::format_to(std::back_inserter(out),
                     "; {} blocks left as they were (correcting them "
                     "made them worse)",
                     seam.blocksLeftAsTheyWere);
    }
    out += '\n';
  }
  return out;
}

double milliseconds(std::chrono::nanoseconds duration) {
  return std::chrono::duration<double, std::milli>(duration).count();
}

double seconds(std::chrono::nanoseconds duration) {
  return std::chrono::duration<double>(duration).count();
}

const char* verdict(bool met) { return met ? "met" : "not met"; }

void family(std::string& out, std::string_view name, std::string_view type, std::string_view help) {
  fmt::format_to(std::back_inserter(out), "# HELP surroundd_{} {}\n# TYPE surroundd_{} {}\n", name,
                 help, name, type);
}

// One sample with one label, in seconds: surroundd_NAME{LABEL="VALUE"} 0.620000
void seconds(std::string& out, std::string_view name, std::string_view label,
             std::string_view value, std::chrono::duration<double> time) {
  fmt::format_to(std::back_inserter(out), "surroundd_{}{{{}=\"{}\"}} {:.6f}\n", name, label, value,
                 time.count());
}

// A Prometheus summary: p50, p90 and p99 from the histogram, with its sum and count.
void summary(std::string& out, std::string_view name, std::string_view labels,
             const DurationHistogram& histogram) {
  const std::string separator = labels.empty() ? "" : ",";
  for (const double q : {0.5, 0.9, 0.99}) {
    fmt::format_to(std::back_inserter(out), "surroundd_{}{{{}{}quantile=\"{}\"}} {:.6f}\n", name,
                   labels, separator, q, seconds(histogram.quantile(q)));
  }
  const std::string braces = labels.empty() ? "" : fmt::format("{{{}}}", labels);
  fmt::format_to(std::back_inserter(out), "surroundd_{}_sum{} {:.6f}\nsurroundd_{}_count{} {}\n",
                 name, braces, seconds(histogram.sum()), name, braces, histogram.count());
}

}  // namespace

const char* toString(Stage stage) {
  constexpr std::array<const char*, kStageCount> kNames{"sync",  "mosaic", "stitch",    "correct",
                                                        "watch", "render", "read-back", "output"};
  return kNames.at(static_cast<std::size_t>(stage));
}

const char* toString(StartupFrom from) {
  constexpr std::array kNames{"process", "reload", "pipeline"};
  return kNames.at(static_cast<std::size_t>(from));
}

std::string frameRateWithLimit(double framesPerSecond) {
  return fmt::format("{:.1f} fps ({}: >= {:g} fps, {})", framesPerSecond,
                     limits::kFrameRateAndLatencyStandard, limits::kMinFramesPerSecond,
                     verdict(limits::frameRateMet(framesPerSecond)));
}

std::string latencyWithLimit(const DurationHistogram& latency) {
  const auto p99 = latency.quantile(0.99);
  return fmt::format("p50 {:.1f} ms  p99 {:.1f} ms ({}: p99 < {} ms, {})",
                     milliseconds(latency.quantile(0.5)), milliseconds(p99),
                     limits::kFrameRateAndLatencyStandard, limits::kMaxLatency.count(),
                     verdict(limits::latencyMet(p99)));
}

std::string startupWithLimits(std::chrono::duration<double> startup, StartupFrom from) {
  const auto exact = std::chrono::duration_cast<std::chrono::nanoseconds>(startup);
  return fmt::format("{:.2f} s after the {} started ({}: <= {:.1f} s, {}; target <= {:.1f} s, {})",
                     startup.count(), toString(from), limits::kFirstPictureStandard,
                     seconds(limits::kMaxFirstPicture), verdict(limits::firstPictureMet(exact)),
                     seconds(limits::kFirstPictureTarget),
                     verdict(limits::firstPictureTargetMet(exact)));
}

std::string viewSwitchWithLimits(const ViewSwitchTime& time) {
  if (!time.settled) {
    return fmt::format("under way, first picture {:.2f} s after the request", time.first.count());
  }
  const auto exact = std::chrono::duration_cast<std::chrono::nanoseconds>(*time.settled);
  return fmt::format(
      "first picture {:.2f} s, settled {:.2f} s after the request ({}: <= {:.1f} s, {}; target "
      "<= {:.1f} s, {})",
      time.first.count(), time.settled->count(), limits::kFirstPictureStandard,
      seconds(limits::kMaxFirstPicture), verdict(limits::firstPictureMet(exact)),
      seconds(limits::kViewSwitchTarget), verdict(limits::viewSwitchTargetMet(exact)));
}

std::string statusLine(const PipelineReport& report) {
  std::string cameras;
  for (const auto& camera : report.cameras) {
    cameras += fmt::format("{}{} {}", cameras.empty() ? "" : ", ", camera.name,
                           capture::toString(camera.health));
  }
  return fmt::format("{:.1f} fps, {} frames dropped by sync, mean skew {:.1f} ms; {}",
                     report.framesPerSecond(), report.sync.totalDropped(),
                     milliseconds(report.sync.meanSpread()), cameras);
}

std::string statusText(const PipelineReport& report) {
  std::string out = fmt::format("{} frame sets in {:.1f} s: {}\n", report.frameSets,
                                report.elapsed.count(), statusLine(report));
  fmt::format_to(std::back_inserter(out),
                 "stale sets skipped: {}; outputs: {} ({} failed, {} pictures dropped); sets a "
                 "stage failed on: {}\n",
                 report.staleDropped, report.outputs, report.failedOutputs, report.outputDropped,
                 report.failedSets);
  if (!report.renderer.empty())
    fmt::format_to(std::back_inserter(out), "render: {}\n", report.renderer);
  for (std::size_t s = 0; s < kStageCount; ++s) {
    const auto& stage = report.stages[s];
    if (stage.count() == 0) continue;
    fmt::format_to(std::back_inserter(out),
                   "stage {:<9} p50 {:7.2f} ms  p99 {:7.2f} ms  ({} sets, {:.1f}/s)\n",
                   toString(static_cast<Stage>(s)), milliseconds(stage.quantile(0.5)),
                   milliseconds(stage.quantile(0.99)), stage.count(),
                   static_cast<double>(stage.count()) / std::max(report.setSpan.count(), 1e-9));
  }
  if (!report.renderer.empty() && !report.gpuTimed) {
    out += "gpu steps not timed: the renderer has no GL_EXT_disjoint_timer_query\n";
  }
  for (std::size_t s = 0; s < render::kGpuSteps && report.gpuTimed; ++s) {
    const auto& step = report.gpuSteps[s];
    if (step.count() == 0) continue;
    fmt::format_to(
        std::back_inserter(out), "gpu {:<11} p50 {:7.2f} ms  p99 {:7.2f} ms  ({} runs)\n",
        render::toString(static_cast<render::GpuStep>(s)), milliseconds(step.quantile(0.5)),
        milliseconds(step.quantile(0.99)), step.count());
  }
  fmt::format_to(std::back_inserter(out), "frame rate: {}\n",
                 frameRateWithLimit(report.framesPerSecond()));
  if (report.latency.count() > 0) {
    fmt::format_to(std::back_inserter(out), "latency capture to output: {}\n",
                   latencyWithLimit(report.latency));
  }
  fmt::format_to(std::back_inserter(out), "first picture: {}\n",
                 report.startup ? startupWithLimits(*report.startup, report.startupFrom)
                                : std::string("none yet"));
  if (report.viewSwitch) {
    fmt::format_to(std::back_inserter(out), "view switch: {}\n",
                   viewSwitchWithLimits(*report.viewSwitch));
  }
  out += watchLines(report);
  out += colourLines(report);
  for (std::size_t c = 0; c < report.cameras.size(); ++c) {
    const auto& camera = report.cameras[c];
    fmt::format_to(std::back_inserter(out),
                   "camera {}: {}{}{}, {} frames, {} faults, {} queued, {} dropped by sync, {} "
                   "sets without it\n",
                   camera.name, capture::toString(camera.health),
                   camera.calibrationDrifting ? ", calibration drifting" : "",
                   camera.mountSuggestion ? mountText(*camera.mountSuggestion) : std::string(),
                   camera.stats.frames, camera.stats.faults, camera.queued,
                   report.sync.unmatchedDropped[c] + report.sync.outOfOrderDropped[c],
                   report.sync.lateMissing[c]);
  }
  return out;
}

std::string calibrationText(const PipelineReport& report) {
  if (report.seams.empty())
    return "the calibration watch is off (calibration_watch.interval_s: 0)\n";
  std::string out = watchLines(report);
  for (const auto& camera : report.cameras) {
    fmt::format_to(std::back_inserter(out), "camera {}: {}{}\n", camera.name,
                   camera.calibrationDrifting ? "calibration drifting" : "no drift seen",
                   camera.mountSuggestion ? mountText(*camera.mountSuggestion) : std::string());
  }
  return out;
}

std::string statusJson(const PipelineReport& report) {
  std::string cameras;
  for (const auto& camera : report.cameras) {
    // Camera names are validated identifiers and health names are fixed words: nothing to escape.
    fmt::format_to(std::back_inserter(cameras), "{}\"{}\": \"{}\"", cameras.empty() ? "" : ", ",
                   camera.name, capture::toString(camera.health));
  }
  return fmt::format(R"({{"fps": {:.1f}, "frames": {}, "cameras": {{{}}}, "latency_ms": {:.1f}, )"
                     R"("dropped_by_sync": {}}})",
                     report.framesPerSecond(), report.frameSets, cameras,
                     milliseconds(report.latency.quantile(0.5)), report.sync.totalDropped());
}

std::string prometheusText(const PipelineReport& report) {
  std::string out;
  family(out, "frame_sets_total", "counter", "Frame sets that went through the pipeline.");
  fmt::format_to(std::back_inserter(out), "surroundd_frame_sets_total {}\n", report.frameSets);
  family(out, "frames_per_second", "gauge",
         fmt::format("Frame sets per second since the pipeline started ({}: at least {:g}).",
                     limits::kFrameRateAndLatencyStandard, limits::kMinFramesPerSecond));
  fmt::format_to(std::back_inserter(out), "surroundd_frames_per_second {:.3f}\n",
                 report.framesPerSecond());
  family(out, "stale_sets_dropped_total", "counter",
         "Live: complete frame sets skipped because a newer one was ready (latest wins).");
  fmt::format_to(std::back_inserter(out), "surroundd_stale_sets_dropped_total {}\n",
                 report.staleDropped);
  family(out, "stage_seconds", "summary", "Time per frame set in each pipeline stage.");
  for (std::size_t s = 0; s < kStageCount; ++s) {
    summary(out, "stage_seconds", fmt::format("stage=\"{}\"", toString(static_cast<Stage>(s))),
            report.stages[s]);
  }
  if (report.gpuTimed) {
    family(out, "gpu_step_seconds", "summary",
           "The GPU's own time of each run of its steps (GL_EXT_disjoint_timer_query): the frames' "
           "or panorama's upload, the stitch pass, a view's draw, its read-back.");
    for (std::size_t s = 0; s < render::kGpuSteps; ++s) {
      summary(out, "gpu_step_seconds",
              fmt::format("step=\"{}\"", render::toString(static_cast<render::GpuStep>(s))),
              report.gpuSteps[s]);
    }
  }
  family(out, "latency_seconds", "summary",
         fmt::format("From a frame set's capture (its oldest frame) to its picture handed to an "
                     "output ({}: p99 below {:g}).",
                     limits::kFrameRateAndLatencyStandard, seconds(limits::kMaxLatency)));
  summary(out, "latency_seconds", "", report.latency);
  family(out, "startup_seconds", "gauge",
         fmt::format("From the run's start (since: the process's, a reload's, or the pipeline's "
                     "after a rebuild) to its first picture handed to an output; absent before "
                     "({}: at most {:g}; target {:g}).",
                     limits::kFirstPictureStandard, seconds(limits::kMaxFirstPicture),
                     seconds(limits::kFirstPictureTarget)));
  if (report.startup) {
    seconds(out, "startup_seconds", "since", toString(report.startupFrom), *report.startup);
  }
  family(out, "view_switch_seconds", "gauge",
         fmt::format("The last switch of view, from its request to the first picture drawn after "
                     "it (picture=\"first\") and to every switched output's new view settled "
                     "(picture=\"settled\"); absent before ({}: at most {:g}; target {:g}).",
                     limits::kFirstPictureStandard, seconds(limits::kMaxFirstPicture),
                     seconds(limits::kViewSwitchTarget)));
  if (report.viewSwitch) {
    seconds(out, "view_switch_seconds", "picture", "first", report.viewSwitch->first);
    if (const auto settled = report.viewSwitch->settled) {
      seconds(out, "view_switch_seconds", "picture", "settled", *settled);
    }
  }

  const auto perCamera = [&](std::string_view name, std::string_view type, std::string_view help,
                             const auto& value) {
    family(out, name, type, help);
    for (std::size_t c = 0; c < report.cameras.size(); ++c) {
      fmt::format_to(std::back_inserter(out), "surroundd_{}{{camera=\"{}\"}} {}\n", name,
                     report.cameras[c].name, value(c));
    }
  };
  perCamera("camera_frames_total", "counter", "Frames each camera delivered.",
            [&](std::size_t c) { return report.cameras[c].stats.frames; });
  perCamera("camera_faults_total", "counter",
            "Faults of each camera: failed reads, frames with decode errors, failed reopenings.",
            [&](std::size_t c) { return report.cameras[c].stats.faults; });
  perCamera("camera_reopens_total", "counter", "Times each camera's lost device was reopened.",
            [&](std::size_t c) { return report.cameras[c].stats.reopens; });
  perCamera("camera_queue_depth", "gauge", "Frames waiting between a camera and the synchronizer.",
            [&](std::size_t c) { return report.cameras[c].queued; });
  perCamera("camera_sync_dropped_total", "counter",
            "Frames the synchronizer dropped (no partner in time, or out of order).",
            [&](std::size_t c) {
              return report.sync.unmatchedDropped[c] + report.sync.outOfOrderDropped[c];
            });
  perCamera("camera_sets_without_total", "counter", "Frame sets sent without this camera.",
            [&](std::size_t c) { return report.sync.lateMissing[c]; });
  perCamera("camera_healthy", "gauge", "1 while the camera is ok, else 0.", [&](std::size_t c) {
    return report.cameras[c].health == capture::CameraHealth::kOk ? 1 : 0;
  });
  family(out, "camera_health", "gauge",
         "1 for the camera's current state (ok, lost, frozen, ...).");
  for (const auto& camera : report.cameras) {
    fmt::format_to(std::back_inserter(out),
                   "surroundd_camera_health{{camera=\"{}\",state=\"{}\"}} 1\n", camera.name,
                   capture::toString(camera.health));
  }
  if (!report.seams.empty()) {
    perCamera("camera_calibration_drifting", "gauge",
              "1 while the drift watch finds the ground under every measured seam of the camera "
              "misaligned (calibration_watch.threshold_cm), else 0.",
              [&](std::size_t c) { return report.cameras[c].calibrationDrifting ? 1 : 0; });
    family(out, "seam_misalignment_cm", "gauge",
           "How far apart the seam's two cameras put the ground under it (phase correlation of "
           "their pictures of a 1.6 m patch); absent before it is measured.");
    for (const auto& seam : report.seams) {
      if (!seam.shiftCm) continue;
      fmt::format_to(std::back_inserter(out),
                     "surroundd_seam_misalignment_cm{{seam=\"{}\"}} {:.2f}\n", seam.name,
                     *seam.shiftCm);
    }
  }
  if (report.mountWatch) {
    family(out, "camera_mount_correction_deg", "gauge",
           "The mount angle change the calibration watch suggests for the camera "
           "(calibration_watch.correct: suggest or apply); absent where none is worth applying.");
    for (const auto& camera : report.cameras) {
      if (!camera.mountSuggestion || camera.mountSuggestion->fault) continue;
      const auto& change = camera.mountSuggestion->changeDeg;
      for (const auto& [axis, value] :
           {std::pair{"yaw", change.yawDeg}, std::pair{"pitch", change.pitchDeg},
            std::pair{"roll", change.rollDeg}}) {
        fmt::format_to(std::back_inserter(out),
                       "surroundd_camera_mount_correction_deg{{camera=\"{}\",axis=\"{}\"}} "
                       "{:.3f}\n",
                       camera.name, axis, value);
      }
    }
    family(out, "camera_mount_fault", "gauge",
           "1 where the calibration watch finds the camera turned past what a mount correction "
           "may make (check its mount), else 0.");
    for (const auto& camera : report.cameras) {
      fmt::format_to(std::back_inserter(out), "surroundd_camera_mount_fault{{camera=\"{}\"}} {}\n",
                     camera.name, camera.mountSuggestion && camera.mountSuggestion->fault ? 1 : 0);
    }
    family(out, "mount_refinement_cpu_seconds_total", "counter",
           "CPU time of the calibration watch's mount refinement thread.");
    fmt::format_to(std::back_inserter(out), "surroundd_mount_refinement_cpu_seconds_total {:.3f}\n",
                   report.mountWatch->cpuSeconds);
    if (report.mountWatch->applying) {
      family(out, "mount_corrections_total", "counter",
             "Mount corrections the calibration watch made (correct: apply), and took back.");
      fmt::format_to(std::back_inserter(out),
                     "surroundd_mount_corrections_total{{outcome=\"applied\"}} {}\n"
                     "surroundd_mount_corrections_total{{outcome=\"taken_back\"}} {}\n",
                     report.mountWatch->applied, report.mountWatch->reverted);
    }
  }
  family(out, "sync_skew_seconds", "gauge", "Mean newest-minus-oldest timestamp within a set.");
  fmt::format_to(std::back_inserter(out), "surroundd_sync_skew_seconds {:.6f}\n",
                 seconds(report.sync.meanSpread()));
  family(out, "output_pictures_dropped_total", "counter",
         "Pictures outputs dropped because they fell behind (live: the newest wins).");
  fmt::format_to(std::back_inserter(out), "surroundd_output_pictures_dropped_total {}\n",
                 report.outputDropped);
  family(out, "outputs_failed_total", "counter", "Outputs dropped after an error.");
  fmt::format_to(std::back_inserter(out), "surroundd_outputs_failed_total {}\n",
                 report.failedOutputs);
  family(out, "frame_sets_failed_total", "counter",
         "Frame sets a stage failed on, dropped (the run goes on).");
  fmt::format_to(std::back_inserter(out), "surroundd_frame_sets_failed_total {}\n",
                 report.failedSets);
  return out;
}

}  // namespace surroundd::daemon
