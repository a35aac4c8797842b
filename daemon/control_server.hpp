#pragma once
// surroundd's control socket (protocol: control_protocol.hpp).
//
// Its own thread runs one poll() loop over every client at once, each with its own deadline: a
// request line within kRequestTimeout, the pipeline's answer within kAnswerTimeout ("busy"
// otherwise), the reply drained within kReplyTimeout (else the client is dropped). No client can
// hold up another or the pipeline: idle, slow and never-reading clients only cost their own
// connection; at kMaxClients a new client takes the place of the longest connected one that has
// sent nothing yet, else of the one that has been sending its request line longest (told "too
// many clients"), so idle connections, even ones that connect again as soon as they are put out,
// cannot lock others out. Lines may end in "\n" or "\r\n". A good request goes to the pipeline
// thread, which answers it in serve() between frame sets; anything slow in an answer (a
// snapshot's PNG encoding) is handed back as `encode` and runs on the server's thread.
//
// The two threads share only the mailbox below (requests waiting, answers given), under its
// mutex; the pipeline and its GL context stay on their own thread.
//
// Error policy: the constructor throws std::runtime_error naming the socket; afterwards nothing a
// client sends can make it throw.

#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "daemon/control/control_protocol.hpp"
#include "daemon/control/unix_socket.hpp"

namespace surroundd::daemon {

// What the pipeline thread answers: a reply, and, where its body is costly to make, the work that
// makes it (run on the control server's thread; it replaces the body).
struct ControlAnswer {
  ControlAnswer(ControlReply r) : reply(std::move(r)) {}  // NOLINT(*-explicit-*): a plain reply
  ControlAnswer(ControlReply r, std::function<std::string()> e)
      : reply(std::move(r)), encode(std::move(e)) {}

  ControlReply reply;
  std::function<std::string()> encode;
};

class ControlServer {
 public:
  using Handler = std::function<ControlAnswer(const ControlRequest&)>;

  static constexpr std::chrono::seconds kRequestTimeout{1};
  static constexpr std::chrono::seconds kAnswerTimeout{10};
  static constexpr std::chrono::seconds kReplyTimeout{5};
  static constexpr std::size_t kMaxClients = 256;
  static constexpr std::size_t kAcceptsPerRound = 32;  // then every client is served once

  // Listens on `path` (mode 0660: the service's user and group).
  explicit ControlServer(std::filesystem::path path);
  ~ControlServer();
  ControlServer(const ControlServer&) = delete;
  ControlServer& operator=(const ControlServer&) = delete;

  const std::filesystem::path& path() const { return path_; }
  // On the pipeline thread: answers every request waiting now with `handle`.
  void serve(const Handler& handle);

 private:
  struct Client;
  static std::vector<Client>::iterator clientToPutOut(std::vector<Client>& clients);
  void run();
  void wake();

  std::filesystem::path path_;
  UnixSocket listener_;
  int wakeFd_[2] = {-1, -1};  // a pipe: written to wake the thread's poll()

  std::mutex mutex_;                                              // guards the mailbox
  std::deque<std::pair<std::uint64_t, ControlRequest>> waiting_;  // by ticket
  std::vector<std::pair<std::uint64_t, ControlAnswer>> answered_;
  bool stopping_ = false;

  std::thread thread_;
};

}  // namespace surroundd::daemon
