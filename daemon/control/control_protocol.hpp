#pragma once
// The control protocol of surroundd's Unix socket, shared by the daemon (ControlServer) and
// surroundctl.
//
// A client connects (SOCK_STREAM), sends one request line of at most kMaxRequestBytes including
// its '\n', and reads one reply; then the server closes the connection.
//   status            -> the status text (frame rate, stages p50/p99, latency, cameras)
//   metrics           -> Prometheus text format
//   view NAME         -> switches every surround output to NAME (top, 360, orbit, split, rear)
//   signal ITEMS      -> the vehicle's signals, e.g. "gear=R steering_deg=-12.5 speed_kmh=3
//                        indicator=left" (vehicle/vehicle_signals.hpp)
//   snapshot          -> the newest output picture as a PNG
//   reload            -> reads the config file again; a bad one is rejected, the old one runs on
//   calibration [status] -> the calibration watch alone
//   calibration accept   -> writes the mounts it corrected into the rig file
//   calibration revert   -> takes its corrections back
// Reply: "ok <body bytes>\n" then the body, or "error <message>\n".
//
// Errors: parsing gives a message for the client (never throws); the client functions throw
// std::runtime_error naming the socket.

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

namespace surroundd::daemon {

inline constexpr std::size_t kMaxRequestBytes = 256;

struct ControlRequest {
  enum class Kind { kStatus, kMetrics, kView, kSignal, kSnapshot, kReload, kCalibration };
  Kind kind = Kind::kStatus;
  std::string argument;  // view: the view's name; signal: its items
};

struct ParsedRequest {
  ControlRequest request;
  std::string error;  // empty when the line was a good request
};

// `line` without its '\n'.
ParsedRequest parseControlRequest(std::string_view line);

struct ControlReply {
  bool ok = false;
  std::string body;  // ok: the payload; error: the message (one line)

  static ControlReply success(std::string body) { return {true, std::move(body)}; }
  static ControlReply failure(std::string message) { return {false, std::move(message)}; }
};

std::string encodeReply(const ControlReply& reply);

// Where the socket is when the config does not say: $RUNTIME_DIRECTORY/control.sock (systemd's
// RuntimeDirectory=, /run/surroundd), else $XDG_RUNTIME_DIR/surroundd/control.sock; empty if
// neither is set.
std::filesystem::path defaultControlSocket();
// The socket surroundctl asks when none is named: `own` (defaultControlSocket(), the user's own
// surroundd) where it exists or where there is no `service` socket, else `service` (the
// service's: a login shell has XDG_RUNTIME_DIR set, and the service's socket was never tried).
std::filesystem::path controlSocketToAsk(const std::filesystem::path& own,
                                         const std::filesystem::path& service);

// Sends `line` and reads the reply, waiting at most `timeout` for it.
ControlReply sendControlRequest(const std::filesystem::path& socket, std::string_view line,
                                std::chrono::milliseconds timeout);

}  // namespace surroundd::daemon
