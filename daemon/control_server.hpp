#pragma once
// surroundd's control socket (protocol: control_protocol.hpp).
//
// Its own thread accepts one client at a time, reads and checks the request (a client that sends
// nothing for a second, too much, or nonsense gets an error reply, and the next client is served),
// then hands a good request to the pipeline thread, which answers it in serve() between frame sets.
// The two threads share only the mailbox below, under its mutex: the pipeline and its GL context
// stay on their own thread, and a slow client never holds up a frame.
//
// Error policy: the constructor throws std::runtime_error naming the socket; afterwards nothing a
// client sends can make it throw.

#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include "daemon/control_protocol.hpp"
#include "daemon/unix_socket.hpp"

namespace surroundd::daemon {

class ControlServer {
 public:
  using Handler = std::function<ControlReply(const ControlRequest&)>;

  // Listens on `path` (mode 0660: the service's user and group).
  explicit ControlServer(std::filesystem::path path);
  ~ControlServer();
  ControlServer(const ControlServer&) = delete;
  ControlServer& operator=(const ControlServer&) = delete;

  const std::filesystem::path& path() const { return path_; }
  // On the pipeline thread: answers the waiting request, if there is one, with `handle`.
  void serve(const Handler& handle);

  // How long a client's request waits for the pipeline thread before it gets "busy".
  static constexpr std::chrono::seconds kAnswerTimeout{10};

 private:
  void run();
  ControlReply answer(UnixSocket& client);

  std::filesystem::path path_;
  UnixSocket listener_;
  int wakeFd_[2] = {-1, -1};  // a pipe: written to stop the thread's poll()

  std::mutex mutex_;  // guards the mailbox: the request the server thread waits on, its reply
  std::condition_variable answered_;
  std::optional<ControlRequest> request_;
  std::uint64_t requestNumber_ = 0;
  std::optional<ControlReply> reply_;

  std::thread thread_;
};

}  // namespace surroundd::daemon
