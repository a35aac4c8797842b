// surroundctl: asks a running surroundd for its status or metrics, switches its view, takes a
// snapshot or makes it reload its config (protocol: daemon/control/control_protocol.hpp).
//
// Exit codes: 0 done, 1 surroundd answered with an error or could not be reached, 2 bad usage.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "common/build_info.hpp"
#include "daemon/control/control_protocol.hpp"

namespace {

using namespace surroundd;

constexpr std::string_view kUsage = R"(usage: surroundctl [--socket PATH] COMMAND

commands:
  status            frame rate, per-stage p50/p99 milliseconds, the GPU's own milliseconds per
                    step where the driver can time them, latency, time to the first picture
                    (each beside its limit), each camera's health
  metrics           the same and more in Prometheus text format
  calibration status  the calibration watch: each seam's ground misalignment, the mount
                    refinement's work, each camera's drift and the mount correction suggested
                    (calibration_watch.correct: suggest or apply) or the fault found, and the
                    corrections applied and taken back (apply)
  calibration accept  write the mounts calibration_watch.correct: apply corrected into the rig
                    file, in place (comments kept; the file before kept beside it as
                    FILE.before-accept)
  calibration revert  take the corrections back: the mounts the run started with (or last
                    accepted), and only suggestions from then on
  view NAME         switch the surround outputs to top, 360, orbit, split or rear
  signal NAME=VALUE...  the vehicle's signals, for vehicles whose signals come from other
                    software: gear=P|R|N|D steering_deg=DEG (the wheel, + left) speed_kmh=KMH
                    indicator=off|left|right|hazard; renew them more often than
                    vehicle_signals.stale_after_s
  snapshot FILE     save the newest output picture as a PNG
  reload            read the config file again (a bad one is rejected; the old one keeps running)

  --socket PATH     surroundd's control socket (default: $RUNTIME_DIRECTORY/control.sock, else
                    $XDG_RUNTIME_DIR/surroundd/control.sock where it exists, else the service's
                    /run/surroundd/control.sock)
  --version         the version, and the optional parts this build has and has not
)";

// A reload restarts the pipeline; building it can take a few seconds.
constexpr std::chrono::seconds kTimeout{30};

int usage(std::string_view message) {
  fmt::print(stderr, "surroundctl: {}\n{}", message, kUsage);
  return 2;
}

// The service's own (systemd/surroundd.service: RuntimeDirectory=surroundd).
constexpr const char* kServiceSocket = "/run/surroundd/control.sock";

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path socket;
  int i = 1;
  if (i < argc && std::string_view(argv[i]) == "--socket") {
    if (i + 1 >= argc) return usage("--socket needs a path");
    socket = argv[i + 1];
    i += 2;
  }
  if (i < argc && (std::string_view(argv[i]) == "--help" || std::string_view(argv[i]) == "-h")) {
    fmt::print("{}", kUsage);
    return 0;
  }
  if (i < argc && std::string_view(argv[i]) == "--version") {
    fmt::print("{}", versionText("surroundctl"));
    return 0;
  }
  if (socket.empty())
    socket = daemon::controlSocketToAsk(daemon::defaultControlSocket(), kServiceSocket);
  if (i >= argc) return usage("no command");
  const std::string_view command = argv[i];
  std::string request(command);
  std::filesystem::path snapshotFile;
  if (command == "view") {
    if (i + 2 != argc) return usage("view needs one NAME");
    request += fmt::format(" {}", argv[i + 1]);
  } else if (command == "signal") {
    if (i + 2 > argc) return usage("signal needs NAME=VALUE items");
    for (int k = i + 1; k < argc; ++k) request += fmt::format(" {}", argv[k]);
  } else if (command == "calibration") {
    const std::string_view what = i + 2 == argc ? argv[i + 1] : "";
    if (what != "status" && what != "accept" && what != "revert") {
      return usage("calibration needs 'status', 'accept' or 'revert'");
    }
    // "calibration" alone is the status, as surroundd has always taken it.
    if (what != "status") request += fmt::format(" {}", what);
  } else if (command == "snapshot") {
    if (i + 2 != argc) return usage("snapshot needs one FILE");
    snapshotFile = argv[i + 1];
  } else if (i + 1 != argc) {
    return usage(fmt::format("'{}' takes no argument", command));
  }

  try {
    const auto reply = daemon::sendControlRequest(socket, request, kTimeout);
    if (!reply.ok) {
      fmt::print(stderr, "surroundctl: surroundd says: {}\n", reply.body);
      return 1;
    }
    if (snapshotFile.empty()) {
      fmt::print("{}", reply.body);
      return 0;
    }
    std::ofstream out(snapshotFile, std::ios::binary);
    out.write(reply.body.data(), static_cast<std::streamsize>(reply.body.size()));
    out.close();
    if (!out) {
      fmt::print(stderr, "surroundctl: cannot write {}\n", snapshotFile.string());
      return 1;
    }
    fmt::print("{}: {} bytes\n", snapshotFile.string(), reply.body.size());
    return 0;
  } catch (const std::exception& e) {
    fmt::print(stderr, "surroundctl: {}\n", e.what());
    return 1;
  }
}
