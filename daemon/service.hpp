#pragma once
// surroundd as a service: runs the pipeline for the config until SIGTERM (or the end of a
// replay), and around it what outlives one pipeline: systemd notifications, the control socket,
// and reloading.
//
// Reload (SIGHUP or `surroundctl reload`): the config file is read again on the pipeline thread.
// A bad one is rejected with its messages and the running pipeline goes on untouched. A good one
// ends the run (every output finalized) and a pipeline for it starts; if that cannot start (a
// camera or output cannot be opened), the previous config is started again; its outputs take
// new names where the files hold the last run's data (daemon/config/output_files.hpp). The control
// socket stays where it was.
//
// The vehicle's signals (`surroundctl signal`, and the CAN bus of vehicle_signals.can, read on
// every loop) outlive runs too: the view rules of
// vehicle_signals are evaluated on every loop, and when the rule that holds changes, every
// surround output switches to its view, or back to the view chosen last by hand when none holds.
//
// Threads: everything here runs on the pipeline thread, but for the signal flags (atomics set by
// the signal handlers) and the control server's own thread (see ControlServer).

#include <atomic>
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "daemon/config/config.hpp"
#include "daemon/control_server.hpp"
#include "daemon/pipeline.hpp"
#include "daemon/service_notifier.hpp"
#include "vehicle/can_signal_reader.hpp"
#include "vehicle/vehicle_signals.hpp"

namespace surroundd::daemon {

struct ServiceSignals {
  std::atomic<bool> stop{false};    // SIGTERM, SIGINT
  std::atomic<bool> reload{false};  // SIGHUP
};

class Service final : public PipelineObserver {
 public:
  // Opens the control socket (throws std::runtime_error naming it if it cannot). `processStart`:
  // where the first run's start-up time counts from (processStartTime()).
  Service(Config config, ServiceSignals& signals, ServiceNotifier notifier,
          std::chrono::steady_clock::time_point processStart);

  // Runs until stopped or the cameras end. Exit code: 0, or 1 when the pipeline could not start
  // or an output failed.
  int run();

  void onLoop(Pipeline& pipeline, std::chrono::steady_clock::time_point now,
              std::uint64_t frameSets) override;
  void onStopping() override;

 private:
  ControlAnswer answer(Pipeline& pipeline, const ControlRequest& request);
  // Reads the config file again; a good config becomes pending and ends the run.
  ControlReply reload();
  // `surroundctl calibration status|accept|revert`.
  ControlReply calibration(Pipeline& pipeline, const std::string& what);
  // Switches the surround outputs when the view rule that holds has changed.
  void followViewRules(Pipeline& pipeline, std::chrono::steady_clock::time_point now);
  std::string vehicleStatus(std::chrono::steady_clock::time_point now) const;

  Config config_;
  std::optional<Config> pending_;  // a good new config, started when the current run has ended
  // Where the next run's start-up time counts from: the process's start, then the reload's.
  RunStart nextStart_;
  std::chrono::steady_clock::time_point reloadedAt_{};  // when pending_ was accepted
  int reloads_ = 0;
  int rebuilds_ = 0;  // in a row, without a frame set between: the pause before the next grows
  ServiceSignals& signals_;
  ServiceNotifier notifier_;
  std::unique_ptr<ControlServer> control_;
  std::atomic<bool> endRun_{false};  // read by Pipeline::run; set on this same thread
  vehicle::VehicleSignalState vehicle_;
  std::unique_ptr<vehicle::CanSignalReader> can_;  // with vehicle_signals.can; opened per run
  ViewKind chosenView_;                            // by hand (surroundctl view), else render.view
  // The view of the rule that held at the last loop; none: no rule held. Unset at each run's
  // start, so that a new pipeline gets the rule's view too.
  std::optional<ViewKind> ruledView_;
  bool ruleChecked_ = false;  // this run
};

}  // namespace surroundd::daemon
