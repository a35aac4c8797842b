#include "daemon/control_server.hpp"

#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

namespace surroundd::daemon {
namespace {

// A client has this long to send its request line.
constexpr std::chrono::seconds kRequestTimeout{1};

}  // namespace

ControlServer::ControlServer(std::filesystem::path path)
    : path_(std::move(path)),
      listener_(UnixSocket::listenOn(
          path_, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write |
                     std::filesystem::perms::group_read | std::filesystem::perms::group_write)) {
  if (::pipe2(wakeFd_, O_CLOEXEC) != 0) {
    throw std::runtime_error(
        fmt::format("control socket: pipe: {}", std::system_category().message(errno)));
  }
  thread_ = std::thread([this] { run(); });
}

ControlServer::~ControlServer() {
  const char stop = 1;
  [[maybe_unused]] const auto written = ::write(wakeFd_[1], &stop, 1);
  {
    // A request waiting for the pipeline thread is answered now: nobody will serve it.
    const std::lock_guard lock(mutex_);
    if (request_ && !reply_) reply_ = ControlReply::failure("surroundd is stopping");
  }
  answered_.notify_all();
  if (thread_.joinable()) thread_.join();
  ::close(wakeFd_[0]);
  ::close(wakeFd_[1]);
}

void ControlServer::run() {
  for (;;) {
    std::array<pollfd, 2> ready{{{listener_.fd(), POLLIN, 0}, {wakeFd_[0], POLLIN, 0}}};
    if (::poll(ready.data(), ready.size(), -1) < 0 && errno != EINTR) return;
    if (ready[1].revents != 0) return;
    while (auto client = listener_.accept()) {
      const ControlReply reply = answer(*client);
      if (!client->sendAll(encodeReply(reply))) spdlog::debug("control: a client left early");
    }
  }
}

ControlReply ControlServer::answer(UnixSocket& client) {
  const auto deadline = UnixSocket::Clock::now() + kRequestTimeout;
  std::array<char, kMaxRequestBytes> buffer{};
  std::size_t size = 0;
  for (;;) {
    const auto n = client.receiveSome(std::span(buffer).subspan(size), deadline);
    if (n < 0) return ControlReply::failure("no complete request line in time");
    if (n == 0) return ControlReply::failure("the request ended without a newline");
    const auto* newline = std::find(buffer.begin() + size, buffer.begin() + size + n, '\n');
    size += static_cast<std::size_t>(n);
    if (newline != buffer.begin() + size) {
      size = static_cast<std::size_t>(newline - buffer.begin());
      break;
    }
    if (size == buffer.size()) {
      return ControlReply::failure(fmt::format("request longer than {} bytes", kMaxRequestBytes));
    }
  }
  const ParsedRequest parsed = parseControlRequest(std::string_view(buffer.data(), size));
  if (!parsed.error.empty()) return ControlReply::failure(parsed.error);

  std::unique_lock lock(mutex_);
  request_ = parsed.request;
  ++requestNumber_;
  reply_.reset();
  const bool done = answered_.wait_for(lock, kAnswerTimeout, [this] { return reply_.has_value(); });
  request_.reset();
  if (!done) return ControlReply::failure("surroundd is busy (no answer in time); try again");
  return *std::exchange(reply_, std::nullopt);
}

void ControlServer::serve(const Handler& handle) {
  std::optional<ControlRequest> request;
  std::uint64_t number = 0;
  {
    const std::lock_guard lock(mutex_);
    if (!request_ || reply_) return;
    request = request_;
    number = requestNumber_;
  }
  // Handled without the lock: a reply may take a while (a snapshot's PNG) and the server thread
  // only waits for it.
  ControlReply reply = handle(*request);
  {
    const std::lock_guard lock(mutex_);
    // Not if the client gave up meanwhile (and perhaps another one asks now).
    if (request_ && requestNumber_ == number) reply_ = std::move(reply);
  }
  answered_.notify_all();
}

}  // namespace surroundd::daemon
