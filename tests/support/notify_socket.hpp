#pragma once
// A datagram socket standing in for systemd's notification socket (NOTIFY_SOCKET), for tests that
// run surroundd and check what it tells systemd, and when.

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

namespace surroundd::testing {

class NotifySocket {
 public:
  struct Message {
    std::string text;
    std::chrono::steady_clock::time_point at;
  };

  explicit NotifySocket(std::filesystem::path path) : path_(std::move(path)) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::snprintf(address.sun_path, sizeof(address.sun_path), "%s", path_.c_str());
    ::bind(fd_, reinterpret_cast<sockaddr*>(&address), sizeof(address));
    timeval timeout{0, 50'000};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
  }
  ~NotifySocket() { ::close(fd_); }
  NotifySocket(const NotifySocket&) = delete;
  NotifySocket& operator=(const NotifySocket&) = delete;

  // The next message, or nullopt when none came within 50 ms.
  std::optional<Message> receive() {
    std::array<char, 4096> buffer{};
    const auto n = ::recv(fd_, buffer.data(), buffer.size(), 0);
    if (n <= 0) return std::nullopt;
    return Message{{buffer.data(), static_cast<std::size_t>(n)}, std::chrono::steady_clock::now()};
  }

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  int fd_ = -1;
};

}  // namespace surroundd::testing
