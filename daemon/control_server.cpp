#include "daemon/control_server.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <optional>
#include <stdexcept>
#include <system_error>

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

namespace surroundd::daemon {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

struct ControlServer::Client {
  enum class Phase { kReading, kWaiting, kWriting };

  Client(UnixSocket s, Clock::time_point requestDeadline)
      : socket(std::move(s)), deadline(requestDeadline) {}

  UnixSocket socket;
  Phase phase = Phase::kReading;
  Clock::time_point deadline;
  std::string line;   // what came so far
  std::string reply;  // encoded, being sent
  std::size_t sent = 0;
  std::uint64_t ticket = 0;
  bool done = false;  // replied, gone, or dropped: closed at the end of the loop's turn

  void answer(const ControlReply& r, Clock::time_point now) {
    reply = encodeReply(r);
    sent = 0;
    phase = Phase::kWriting;
    deadline = now + kReplyTimeout;
  }
};

ControlServer::ControlServer(std::filesystem::path path)
    : path_(std::move(path)),
      listener_(UnixSocket::listenOn(
          path_, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write |
                     std::filesystem::perms::group_read | std::filesystem::perms::group_write)) {
  if (::pipe2(wakeFd_, O_CLOEXEC | O_NONBLOCK) != 0) {
    throw std::runtime_error(
        fmt::format("control socket: pipe: {}", std::system_category().message(errno)));
  }
  thread_ = std::thread([this] { run(); });
}

ControlServer::~ControlServer() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake();
  if (thread_.joinable()) thread_.join();
  ::close(wakeFd_[0]);
  ::close(wakeFd_[1]);
}

void ControlServer::wake() {
  const char byte = 1;
  [[maybe_unused]] const auto written = ::write(wakeFd_[1], &byte, 1);  // full: awake already
}

void ControlServer::serve(const Handler& handle) {
  std::deque<std::pair<std::uint64_t, ControlRequest>> requests;
  {
    const std::lock_guard lock(mutex_);
    if (waiting_.empty()) return;
    requests.swap(waiting_);
  }
  // Handled without the lock: the server thread goes on serving other clients meanwhile.
  std::vector<std::pair<std::uint64_t, ControlAnswer>> answers;
  answers.reserve(requests.size());
  for (const auto& [ticket, request] : requests) answers.emplace_back(ticket, handle(request));
  {
    const std::lock_guard lock(mutex_);
    for (auto& answer : answers) answered_.push_back(std::move(answer));
  }
  wake();
}

// The client that makes room for a new one at kMaxClients: the longest connected of those that
// have sent nothing yet (no byte read, none waiting to be), else the longest still sending its
// request line (clients are in arrival order); none when every one waits on the pipeline. Idle
// clients that connect again as soon as they are put out once took the place of the one client
// with a request on its way, which had come last: every `status` failed.
std::vector<ControlServer::Client>::iterator ControlServer::clientToPutOut(
    std::vector<Client>& clients) {
  const auto sentNothing = [](const Client& c) {
    int waiting = 0;
    return c.phase == Client::Phase::kReading && c.line.empty() &&
           ::ioctl(c.socket.fd(), FIONREAD, &waiting) == 0 && waiting == 0;
  };
  if (const auto idle = std::ranges::find_if(clients, sentNothing); idle != clients.end()) {
    return idle;
  }
  return std::ranges::find_if(clients,
                              [](const Client& c) { return c.phase == Client::Phase::kReading; });
}

void ControlServer::run() {
  std::vector<Client> clients;
  std::vector<pollfd> polled;
  std::uint64_t nextTicket = 1;
  std::array<char, kMaxRequestBytes> buffer{};
  for (;;) {
    const auto now = Clock::now();
    // The pipeline's answers, to the clients still waiting for them.
    std::vector<std::pair<std::uint64_t, ControlAnswer>> answers;
    bool stopping = false;
    {
      const std::lock_guard lock(mutex_);
      answers.swap(answered_);
      stopping = stopping_;
    }
    for (auto& [ticket, answer] : answers) {
      const auto client = std::ranges::find_if(clients, [id = ticket](const Client& c) {
        return c.phase == Client::Phase::kWaiting && c.ticket == id;
      });
      if (client == clients.end()) continue;  // it gave up or left
      if (answer.encode) {
        try {
          answer.reply.body = answer.encode();
        } catch (const std::exception& e) {
          answer.reply = ControlReply::failure(e.what());
        }
      }
      client->answer(answer.reply, now);
    }
    if (stopping) {
      // Best effort: whoever still waits hears why, without blocking.
      for (auto& client : clients) {
        if (client.phase == Client::Phase::kWriting) continue;
        const std::string reply = encodeReply(ControlReply::failure("surroundd is stopping"));
        [[maybe_unused]] const auto n =
            ::send(client.socket.fd(), reply.data(), reply.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
      }
      return;
    }
    // Deadlines.
    for (auto& client : clients) {
      if (now < client.deadline) continue;
      if (client.phase == Client::Phase::kReading) {
        client.answer(ControlReply::failure("no complete request line in time"), now);
      } else if (client.phase == Client::Phase::kWaiting) {
        {
          const std::lock_guard lock(mutex_);
          std::erase_if(waiting_, [&](const auto& w) { return w.first == client.ticket; });
        }
        client.answer(ControlReply::failure("surroundd is busy (no answer in time); try again"),
                      now);
      } else {
        client.done = true;  // it would not read its reply
      }
    }
    std::erase_if(clients, [](const Client& c) { return c.done; });

    polled.assign({{listener_.fd(), POLLIN, 0}, {wakeFd_[0], POLLIN, 0}});
    auto nextDeadline = Clock::time_point::max();
    for (const auto& client : clients) {
      const short events = client.phase == Client::Phase::kReading   ? POLLIN
                           : client.phase == Client::Phase::kWriting ? POLLOUT
                                                                     : 0;
      polled.push_back({client.socket.fd(), events, 0});
      nextDeadline = std::min(nextDeadline, client.deadline);
    }
    int timeoutMs = -1;
    if (nextDeadline != Clock::time_point::max()) {
      timeoutMs = static_cast<int>(std::clamp<long long>(
          std::chrono::ceil<std::chrono::milliseconds>(nextDeadline - Clock::now()).count(), 0,
          1000));
    }
    if (::poll(polled.data(), polled.size(), timeoutMs) < 0 && errno != EINTR) {
      spdlog::error("control socket: poll: {}", std::system_category().message(errno));
      return;
    }
    const auto after = Clock::now();
    if (polled[1].revents != 0) {
      char drain[64];
      while (::read(wakeFd_[0], drain, sizeof drain) > 0) {
      }
    }
    for (std::size_t k = 0; k < clients.size(); ++k) {
      Client& client = clients[k];
      const short revents = polled[k + 2].revents;
      if (revents == 0) continue;
      if (client.phase == Client::Phase::kReading) {
        const auto n = ::recv(client.socket.fd(), buffer.data(), buffer.size(), MSG_DONTWAIT);
        if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
        if (n <= 0) {
          client.answer(ControlReply::failure("the request ended without a newline"), after);
          continue;
        }
        client.line.append(buffer.data(), static_cast<std::size_t>(n));
        const auto newline = client.line.find('\n');
        if (newline == std::string::npos) {
          if (client.line.size() >= kMaxRequestBytes) {
            client.answer(ControlReply::failure(
                              fmt::format("request longer than {} bytes", kMaxRequestBytes)),
                          after);
          }
          continue;
        }
        std::string_view line(client.line.data(), newline);
        if (line.ends_with('\r')) line.remove_suffix(1);  // CRLF, as telnet and nc -C send
        const ParsedRequest parsed = parseControlRequest(line);
        if (!parsed.error.empty()) {
          client.answer(ControlReply::failure(parsed.error), after);
          continue;
        }
        client.phase = Client::Phase::kWaiting;
        client.ticket = nextTicket++;
        client.deadline = after + kAnswerTimeout;
        const std::lock_guard lock(mutex_);
        waiting_.emplace_back(client.ticket, parsed.request);
      } else if (client.phase == Client::Phase::kWriting) {
        const auto n = ::send(client.socket.fd(), client.reply.data() + client.sent,
                              client.reply.size() - client.sent, MSG_DONTWAIT | MSG_NOSIGNAL);
        if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
        if (n <= 0) {
          spdlog::debug("control: a client left before its reply");
          client.done = true;
          continue;
        }
        client.sent += static_cast<std::size_t>(n);
        client.done = client.sent == client.reply.size();
      } else if ((revents & (POLLHUP | POLLERR)) != 0) {
        client.done = true;  // left while waiting: its answer goes nowhere
      }
    }
    std::erase_if(clients, [](const Client& c) { return c.done; });
    if (polled[0].revents != 0) {
      // A bounded number per round: clients that connect again as fast as they are put out
      // kept this loop accepting, and no request was read or answered.
      for (std::size_t accepted = 0; accepted < kAcceptsPerRound; ++accepted) {
        auto socket = listener_.accept();
        if (!socket) break;
        if (clients.size() >= kMaxClients) {
          const auto oldest = clientToPutOut(clients);
          const std::string reply = encodeReply(ControlReply::failure(
              fmt::format("too many clients ({} at once); try again", kMaxClients)));
          const int fd = oldest != clients.end() ? oldest->socket.fd() : socket->fd();
          [[maybe_unused]] const auto n =
              ::send(fd, reply.data(), reply.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
          if (oldest == clients.end()) continue;  // every place waits on the pipeline
          clients.erase(oldest);
        }
        clients.emplace_back(std::move(*socket), after + kRequestTimeout);
      }
    }
  }
}

}  // namespace surroundd::daemon
