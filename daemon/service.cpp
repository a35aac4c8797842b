#include "daemon/service.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <malloc.h>
#include <spdlog/spdlog.h>

#include "daemon/config/rig_update.hpp"
#include "daemon/config/view_rules.hpp"
#include "daemon/mount_corrections.hpp"
#include "render/outputs/image_file.hpp"
#include "render/view_camera.hpp"

namespace surroundd::daemon {
namespace {

void logSummary(const RunSummary& summary) {
  spdlog::info(
      "{} frame sets in {:.2f} s: {:.1f} fps; sync dropped {} frames, max spread {:.2f} ms",
      summary.frameSets, summary.wallTime.count(), summary.framesPerSecond(),
      summary.sync.totalDropped(),
      std::chrono::duration<double, std::milli>(summary.sync.maxSpread).count());
  if (summary.failedSets > 0) {
    spdlog::warn("{} frame sets failed and were dropped", summary.failedSets);
  }
  const auto& latency = summary.report.latency;
  if (latency.count() > 0) {
    spdlog::info("latency capture to output: p50 {:.1f} ms, p99 {:.1f} ms ({} pictures)",
                 std::chrono::duration<double, std::milli>(latency.quantile(0.5)).count(),
                 std::chrono::duration<double, std::milli>(latency.quantile(0.99)).count(),
                 latency.count());
  }
  for (std::size_t c = 0; c < summary.cameras.size(); ++c) {
    spdlog::info(
        "camera '{}': {} frames, {} faults, {} dropped unmatched, {} out of order, {} sets sent "
        "without it",
        summary.cameraNames[c], summary.cameras[c].frames, summary.cameras[c].faults,
        summary.sync.unmatchedDropped[c], summary.sync.outOfOrderDropped[c],
        summary.sync.lateMissing[c]);
  }
  for (const auto& output : summary.outputs) spdlog::info("wrote {}", output);
}

// A run allocates its frame pools, look-up table, panorama, meshes and encoder buffers afresh (a
// few hundred MB for four 1280x720 cameras) from the threads it starts, and frees them when it
// ends. glibc keeps what a thread frees in that thread's arena for later allocations there, and
// raises its mmap threshold each time a large mapped block is freed, so the next run's large
// buffers come from the arenas instead of fresh mappings — while its new threads land on other
// arenas and allocate again. What stayed between runs grew with each reload (272, 340, 348, 360,
// 362 MB over the first five reloads of the soak, scripts/soak.sh; ~100 MB over ~30 reloads in
// issue 18.10) until every arena held enough. A reload is rare and costs a pipeline start anyway:
// hand what the finished run freed back to the system there, once.
void releaseFreedMemory() {
  const auto start = std::chrono::steady_clock::now();
  const int released = malloc_trim(0);
  spdlog::debug(
      "memory: freed memory {}returned to the system in {:.1f} ms", released != 0 ? "" : "(none) ",
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
}

// vehicle_signals.stale_after_s as the signal state's clock counts.
vehicle::VehicleSignalState::Clock::duration staleAfter(const Config& config) {
  return std::chrono::duration_cast<vehicle::VehicleSignalState::Clock::duration>(
      std::chrono::duration<double>(config.vehicleSignals.staleAfterS));
}

}  // namespace

Service::Service(Config config, ServiceSignals& signals, ServiceNotifier notifier,
                 std::chrono::steady_clock::time_point processStart)
    : config_(std::move(config)),
      nextStart_{processStart, StartupFrom::kProcess},
      signals_(signals),
      notifier_(std::move(notifier)),
      vehicle_(staleAfter(config_)),
      chosenView_(config_.render.view) {
  const auto socket =
      config_.control.socket.empty() ? defaultControlSocket() : config_.control.socket;
  if (socket.empty()) {
    spdlog::info("control: no socket (set control.socket, or run under systemd)");
    return;
  }
  control_ = std::make_unique<ControlServer>(socket);
  spdlog::info("control: listening on {}", socket.string());
}

int Service::run() {
  std::optional<Config> previous;  // to go back to when a reloaded config cannot start
  for (;;) {
    std::unique_ptr<Pipeline> pipeline;
    try {
      pipeline = std::make_unique<Pipeline>(config_, nextStart_);
    } catch (const std::exception& e) {
      if (!previous) {
        spdlog::critical("{}", e.what());
        return 1;
      }
      spdlog::error("reload: the new config cannot start ({}); starting the previous one again",
                    e.what());
      config_ = *std::exchange(previous, std::nullopt);
      ++reloads_;
      continue;
    }
    endRun_ = false;
    ruledView_.reset();
    ruleChecked_ = false;
    vehicle_.setStaleAfter(staleAfter(config_));
    can_.reset();
    if (config_.vehicleSignals.can) {
      can_ = std::make_unique<vehicle::CanSignalReader>(*config_.vehicleSignals.can,
                                                        vehicle::makeSocketCanBus(),
                                                        std::chrono::steady_clock::now());
    }
    const RunSummary summary = pipeline->run(endRun_, this);
    pipeline.reset();
    releaseFreedMemory();
    logSummary(summary);
    if (summary.rebuild && !signals_.stop) {
      // The same config again, after a pause that grows while rebuilds keep failing.
      rebuilds_ = summary.frameSets > 0 ? 1 : rebuilds_ + 1;
      const auto pause =
          std::min(std::chrono::seconds(1 << std::min(rebuilds_ - 1, 5)), std::chrono::seconds(30));
      spdlog::warn("rebuilding the pipeline in {} s", pause.count());
      for (auto until = std::chrono::steady_clock::now() + pause;
           std::chrono::steady_clock::now() < until && !signals_.stop;) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
      if (!signals_.stop) {
        nextStart_ = {};  // a rebuild counts from its own start, after the pause
        continue;
      }
    }
    if (!pending_ || signals_.stop) return summary.failedOutputs == 0 ? 0 : 1;
    previous = std::exchange(config_, *std::exchange(pending_, std::nullopt));
    // The gap the reload leaves in the pictures: the old run's finalizing counts too. If the new
    // config cannot start, the previous one's first picture still counts from here.
    nextStart_ = {reloadedAt_, StartupFrom::kReload};
    ++reloads_;
    spdlog::info("reload: starting the pipeline for the new config (reload {})", reloads_);
  }
}

void Service::onLoop(Pipeline& pipeline, std::chrono::steady_clock::time_point now,
                     std::uint64_t frameSets) {
  if (signals_.stop) endRun_ = true;
  if (signals_.reload.exchange(false)) reload();
  if (control_) {
    control_->serve([&](const ControlRequest& request) { return answer(pipeline, request); });
  }
  if (can_) can_->poll(vehicle_, now);
  pipeline.setVehicleSignals(vehicle_.at(now));
  followViewRules(pipeline, now);
  // With every output failed nothing is recorded: the watchdog is no longer fed, so systemd
  // restarts the service if the outputs do not come back first.
  const bool outputsWork = pipeline.outputsWork();
  notifier_.tick(now, frameSets, outputsWork);
  if (notifier_.statusDue(now)) {
    const std::string line = statusLine(pipeline.report());
    notifier_.status(now,
                     outputsWork ? line : "degraded: every output has failed, retrying; " + line);
  }
}

void Service::followViewRules(Pipeline& pipeline, std::chrono::steady_clock::time_point now) {
  const ViewRule* rule = ruleThatHolds(config_.vehicleSignals.viewRules, vehicle_.at(now));
  const std::optional<ViewKind> ruled = rule != nullptr ? std::optional(rule->view) : std::nullopt;
  if (ruleChecked_ && ruled == ruledView_) return;
  // A run starts in its outputs' own views: only a rule that holds switches them then.
  const bool first = !ruleChecked_;
  ruleChecked_ = true;
  ruledView_ = ruled;
  if (first && !ruled) return;
  const ViewKind view = ruled.value_or(chosenView_);
  spdlog::info("view rules: {} ({})", toString(view),
               rule != nullptr ? describe(*rule) : "no rule holds: the view chosen last");
  pipeline.setView(view);
}

std::string Service::vehicleStatus(std::chrono::steady_clock::time_point now) const {
  const ViewRule* rule = ruleThatHolds(config_.vehicleSignals.viewRules, vehicle_.at(now));
  return fmt::format("vehicle: {}{}\nview rule: {}\n", vehicle_.describe(now),
                     can_ ? "; " + can_->describe(now) : std::string(),
                     rule != nullptr ? describe(*rule) : "none holds");
}

void Service::onStopping() {
  if (pending_ && !signals_.stop) {
    notifier_.reloading();
  } else {
    notifier_.stopping();
  }
}

ControlReply Service::reload() {
  spdlog::info("reload: reading {}", config_.file.string());
  try {
    Config fresh = loadConfig(config_.file);
    for (const auto& warning : fresh.warnings) spdlog::warn("reload: {}", warning);
    if (fresh.control != config_.control) {
      spdlog::warn("reload: control.socket changes only when surroundd restarts");
    }
    pending_ = std::move(fresh);
    reloadedAt_ = std::chrono::steady_clock::now();
    endRun_ = true;
    return ControlReply::success("the new config is good; restarting the pipeline with it\n");
  } catch (const ConfigError& e) {
    std::string messages;
    for (const auto& message : e.messages()) {
      spdlog::error("reload rejected: {}", message);
      messages += (messages.empty() ? "" : "; ") + message;
    }
    return ControlReply::failure("config rejected, the running one goes on: " + messages);
  }
}

ControlReply Service::calibration(Pipeline& pipeline, const std::string& what) {
  if (what.empty() || what == "status") {
    return ControlReply::success(calibrationText(pipeline.report()));
  }
  MountCorrections* mounts = pipeline.mountCorrections();
  if (mounts == nullptr) {
    return ControlReply::failure("no calibration watch runs: no output shows the panorama");
  }
  if (what == "revert") return ControlReply::success(mounts->revert());
  const auto corrected = mounts->correctedMounts();
  if (corrected.empty()) {
    return ControlReply::failure(
        "no mount corrected since the run started (or was last accepted): nothing to accept");
  }
  if (!config_.rigFile) {
    std::vector<std::string> blocks;
    for (const auto& [name, pose] : corrected) {
      const auto angles = processing::mountAnglesFromRotation(pose.rotation);
      blocks.push_back(fmt::format(
          "camera '{}': mount: {{x_m: {:.4f}, y_m: {:.4f}, z_m: {:.4f}, yaw_deg: {:.3f}, "
          "pitch_deg: {:.3f}, roll_deg: {:.3f}}}",
          name, pose.position[0], pose.position[1], pose.position[2], angles.yawDeg,
          angles.pitchDeg, angles.rollDeg));
    }
    return ControlReply::failure(
        fmt::format("{} writes its cameras inline, not in a rig file: nothing is written; copy "
                    "them: {}",
                    config_.file.string(), fmt::join(blocks, "; ")));
  }
  const std::filesystem::path& rig = *config_.rigFile;
  const std::filesystem::path before = rig.string() + ".before-accept";
  try {
    std::filesystem::copy_file(rig, before, std::filesystem::copy_options::overwrite_existing);
    updateRigMounts(rig, corrected,
                    "corrected from the road by surroundd's calibration watch, accepted");
  } catch (const std::exception& e) {
    spdlog::error("calibration accept: {}", e.what());
    return ControlReply::failure(fmt::format("the rig is left as it was: {}", e.what()));
  }
  mounts->accepted();
  std::vector<std::string> names;
  names.reserve(corrected.size());
  for (const auto& mount : corrected) names.push_back(fmt::format("'{}'", mount.first));
  spdlog::info(
      "calibration accept: camera {}'s corrected mount written into {} (the file before: "
      "{})",
      fmt::join(names, ", "), rig.string(), before.string());
  return ControlReply::success(
      fmt::format("wrote the corrected mount of camera {} into {} (the file before: {})\n",
                  fmt::join(names, ", "), rig.string(), before.string()));
}

ControlAnswer Service::answer(Pipeline& pipeline, const ControlRequest& request) {
  using Kind = ControlRequest::Kind;
  switch (request.kind) {
    case Kind::kStatus:
      return ControlReply::success(statusText(pipeline.report()) +
                                   vehicleStatus(std::chrono::steady_clock::now()));
    case Kind::kMetrics:
      return ControlReply::success(prometheusText(pipeline.report()));
    case Kind::kCalibration:
      return calibration(pipeline, request.argument);
    case Kind::kView: {
      const auto view = render::parseViewKind(request.argument);
      if (!view) {
        return ControlReply::failure(
            fmt::format("unknown view '{}' ({})", request.argument, render::viewNameList(", ")));
      }
      chosenView_ = *view;
      pipeline.setView(*view);
      return ControlReply::success(fmt::format("view {}\n", request.argument));
    }
    case Kind::kSignal: {
      const auto now = std::chrono::steady_clock::now();
      if (const auto error = vehicle_.set(request.argument, now)) {
        return ControlReply::failure("signal: " + *error);
      }
      // The view it brings up, and the guidelines, right away: before the next frame set.
      pipeline.setVehicleSignals(vehicle_.at(now));
      followViewRules(pipeline, now);
      return ControlReply::success(vehicle_.describe(now) + "\n");
    }
    case Kind::kSnapshot: {
      const cv::Mat picture = pipeline.latestPicture();
      if (picture.empty()) return ControlReply::failure("no picture yet");
      // A copy here (the pipeline's buffer changes with the next set); the PNG is encoded on the
      // control server's thread, not this one.
      return {ControlReply::success({}), [copy = picture.clone()] {
                const std::vector<std::uint8_t> png = render::encodePng(copy);
                return std::string(png.begin(), png.end());
              }};
    }
    case Kind::kReload:
      return reload();
  }
  return ControlReply::failure("unknown request");
}

}  // namespace surroundd::daemon
