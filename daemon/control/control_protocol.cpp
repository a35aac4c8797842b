#include "daemon/control/control_protocol.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <system_error>

#include <fmt/format.h>

#include "daemon/control/unix_socket.hpp"

namespace surroundd::daemon {
namespace {

bool printable(std::string_view text) {
  return std::ranges::all_of(text, [](char c) { return c >= 0x20 && c < 0x7f; });
}

}  // namespace

ParsedRequest parseControlRequest(std::string_view line) {
  using Kind = ControlRequest::Kind;
  if (!printable(line)) return {{}, "request has control or non-ASCII characters"};
  const auto space = line.find(' ');
  const std::string_view command = line.substr(0, space);
  const std::string_view argument = space == std::string_view::npos ? "" : line.substr(space + 1);
  enum class Argument { kNone, kRequired, kOptional };
  struct Known {
    std::string_view name;
    Kind kind;
    Argument argument;
  };
  constexpr std::array<Known, 7> kCommands{
      {{"status", Kind::kStatus, Argument::kNone},
       {"metrics", Kind::kMetrics, Argument::kNone},
       {"calibration", Kind::kCalibration, Argument::kOptional},
       {"view", Kind::kView, Argument::kRequired},
       {"signal", Kind::kSignal, Argument::kRequired},
       {"snapshot", Kind::kSnapshot, Argument::kNone},
       {"reload", Kind::kReload, Argument::kNone}}};
  const auto* known = std::ranges::find(kCommands, command, &Known::name);
  if (known == kCommands.end()) {
    return {{},
            fmt::format("unknown request '{}' (status, metrics, calibration [status|accept|"
                        "revert], view NAME, signal ITEMS, snapshot, reload)",
                        command)};
  }
  if (known->argument == Argument::kRequired && argument.empty()) {
    return {{}, fmt::format("'{}' needs an argument", command)};
  }
  if (known->kind == Kind::kCalibration && !argument.empty() && argument != "status" &&
      argument != "accept" && argument != "revert") {
    return {{}, fmt::format("'calibration' takes status, accept or revert, not '{}'", argument)};
  }
  if (known->argument == Argument::kNone && space != std::string_view::npos) {
    return {{}, fmt::format("'{}' takes no argument", command)};
  }
  return {{known->kind, std::string(argument)}, {}};
}

std::string encodeReply(const ControlReply& reply) {
  if (reply.ok) return fmt::format("ok {}\n", reply.body.size()) + reply.body;
  std::string message = reply.body;
  std::ranges::replace(message, '\n', ' ');
  return fmt::format("error {}\n", message);
}

// NOLINTBEGIN(concurrency-mt-unsafe): the environment is read at start-up and never written.
std::filesystem::path defaultControlSocket() {
  if (const char* runtime = std::getenv("RUNTIME_DIRECTORY"); runtime != nullptr && *runtime) {
    // systemd may list several directories separated by ':'; ours is the first.
    const std::string_view first(runtime, std::strcspn(runtime, ":"));
    return std::filesystem::path(first) / "control.sock";
  }
  if (const char* user = std::getenv("XDG_RUNTIME_DIR"); user != nullptr && *user) {
    return std::filesystem::path(user) / "surroundd" / "control.sock";
  }
  return {};
}
// NOLINTEND(concurrency-mt-unsafe)

std::filesystem::path controlSocketToAsk(const std::filesystem::path& own,
                                         const std::filesystem::path& service) {
  std::error_code error;
  if (own.empty() ||
      (!std::filesystem::exists(own, error) && std::filesystem::exists(service, error))) {
    return service;
  }
  return own;
}

ControlReply sendControlRequest(const std::filesystem::path& socket, std::string_view line,
                                std::chrono::milliseconds timeout) {
  const auto fail = [&](std::string_view what) {
    return std::runtime_error(fmt::format("{}: {}", socket.string(), what));
  };
  UnixSocket client = UnixSocket::connectTo(socket);  // throws naming the socket
  const std::string request = std::string(line) + "\n";
  if (!client.sendAll(request))
    throw fail(fmt::format("cannot send: {}", std::system_category().message(errno)));
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::string received;
  std::array<char, 65536> buffer{};
  for (;;) {
    const auto n = client.receiveSome(buffer, deadline);
    if (n < 0) throw fail("no reply in time");
    if (n == 0) break;
    received.append(buffer.data(), static_cast<std::size_t>(n));
  }
  const auto newline = received.find('\n');
  if (newline == std::string::npos) throw fail("the reply was cut off");
  const std::string_view header(received.data(), newline);
  if (header.starts_with("error ")) return ControlReply::failure(std::string(header.substr(6)));
  std::size_t size = 0;
  if (!header.starts_with("ok ") ||
      std::sscanf(std::string(header.substr(3)).c_str(), "%zu", &size) != 1 ||
      received.size() - newline - 1 != size) {
    throw fail(fmt::format("malformed reply '{}'", header.substr(0, 80)));
  }
  return ControlReply::success(received.substr(newline + 1));
}

}  // namespace surroundd::daemon
