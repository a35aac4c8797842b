#include "daemon/control/unix_socket.hpp"

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>
#include <utility>

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

namespace surroundd::daemon {
namespace {

// A client that stops reading must not hold the server: its reply is dropped after this.
constexpr timeval kSendTimeout{2, 0};

std::runtime_error failure(const std::filesystem::path& path, std::string_view what) {
  return std::runtime_error(fmt::format("control socket {}: {}", path.string(), what));
}

sockaddr_un addressOf(const std::filesystem::path& path) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (path.native().size() >= sizeof(address.sun_path)) {
    throw failure(path, fmt::format("path longer than {} bytes", sizeof(address.sun_path) - 1));
  }
  std::memcpy(address.sun_path, path.c_str(), path.native().size());
  return address;
}

int newSocket(const std::filesystem::path& path) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) throw failure(path, std::system_category().message(errno));
  return fd;
}

bool connects(int fd, const sockaddr_un& address) {
  return ::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0;
}

}  // namespace

UnixSocket UnixSocket::listenOn(const std::filesystem::path& path, std::filesystem::perms mode) {
  const sockaddr_un address = addressOf(path);
  std::error_code error;
  std::filesystem::create_directories(path.parent_path(), error);
  if (error) throw failure(path, fmt::format("cannot create its folder: {}", error.message()));
  if (std::filesystem::is_socket(path)) {
    UnixSocket probe(newSocket(path), {});
    if (connects(probe.fd_, address)) throw failure(path, "in use by a running server");
    std::filesystem::remove(path, error);  // left by a process that is gone
  }
  UnixSocket server(newSocket(path), {});
  if (::bind(server.fd_, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
    throw failure(path, fmt::format("cannot bind: {}", std::system_category().message(errno)));
  }
  server.ownedPath_ = path;
  std::filesystem::permissions(path, mode, error);
  if (error) throw failure(path, fmt::format("cannot set its mode: {}", error.message()));
  if (::listen(server.fd_, SOMAXCONN) != 0) {
    throw failure(path, fmt::format("cannot listen: {}", std::system_category().message(errno)));
  }
  ::fcntl(server.fd_, F_SETFL, ::fcntl(server.fd_, F_GETFL) | O_NONBLOCK);
  return server;
}

UnixSocket UnixSocket::connectTo(const std::filesystem::path& path) {
  const sockaddr_un address = addressOf(path);
  UnixSocket client(newSocket(path), {});
  if (!connects(client.fd_, address)) {
    throw failure(path, fmt::format("cannot connect: {} (is surroundd running, with this socket?)",
                                    std::system_category().message(errno)));
  }
  return client;
}

UnixSocket::UnixSocket(UnixSocket&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), ownedPath_(std::exchange(other.ownedPath_, {})) {}

UnixSocket& UnixSocket::operator=(UnixSocket&& other) noexcept {
  if (this != &other) {
    UnixSocket old(std::move(*this));
    fd_ = std::exchange(other.fd_, -1);
    ownedPath_ = std::exchange(other.ownedPath_, {});
  }
  return *this;
}

UnixSocket::~UnixSocket() {
  if (fd_ >= 0) ::close(fd_);
  if (!ownedPath_.empty()) {
    std::error_code ignored;
    std::filesystem::remove(ownedPath_, ignored);
  }
}

std::optional<UnixSocket> UnixSocket::accept() const {
  const int client = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC);
  if (client < 0) return std::nullopt;
  ::setsockopt(client, SOL_SOCKET, SO_SNDTIMEO, &kSendTimeout, sizeof(kSendTimeout));
  return UnixSocket(client, {});
}

bool UnixSocket::sendAll(std::string_view data) const {
  while (!data.empty()) {
    const auto n = ::send(fd_, data.data(), data.size(), MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

ssize_t UnixSocket::receiveSome(std::span<char> buffer, Clock::time_point deadline) const {
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) return -1;
    pollfd ready{fd_, POLLIN, 0};
    const int polled = ::poll(&ready, 1, static_cast<int>(left));
    if (polled < 0 && errno == EINTR) continue;
    if (polled <= 0) return -1;
    const auto n = ::recv(fd_, buffer.data(), buffer.size(), 0);
    if (n < 0 && errno == EINTR) continue;
    return n;
  }
}

}  // namespace surroundd::daemon
