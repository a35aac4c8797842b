#pragma once
// A Unix stream socket, owned (closed on destruction; a listening socket also removes its path).
//
// Error policy: listenOn() and connectTo() throw std::runtime_error naming the path; sending and
// receiving report failure through their results, for the caller to answer or drop the client.

#include <chrono>
#include <filesystem>
#include <optional>
#include <span>
#include <string_view>

#include <sys/types.h>

namespace surroundd::daemon {

class UnixSocket {
 public:
  using Clock = std::chrono::steady_clock;

  // Binds `path` with file mode `mode`, creating its folder. A path left by a process that is gone
  // is replaced; one a live server answers on is refused ("in use").
  static UnixSocket listenOn(const std::filesystem::path& path, std::filesystem::perms mode);
  static UnixSocket connectTo(const std::filesystem::path& path);

  UnixSocket(UnixSocket&& other) noexcept;
  UnixSocket& operator=(UnixSocket&& other) noexcept;
  UnixSocket(const UnixSocket&) = delete;
  UnixSocket& operator=(const UnixSocket&) = delete;
  ~UnixSocket();

  int fd() const { return fd_; }
  // A connected client, or nullopt if none is waiting (the listening socket is non-blocking).
  std::optional<UnixSocket> accept() const;
  // Whole `data`, or false (peer gone, or stuck past the send timeout).
  bool sendAll(std::string_view data) const;
  // Up to buffer.size() bytes: > 0 received, 0 at the end of the stream, -1 on error or when
  // `deadline` passed first.
  ssize_t receiveSome(std::span<char> buffer, Clock::time_point deadline) const;

 private:
  UnixSocket(int fd, std::filesystem::path ownedPath) : fd_(fd), ownedPath_(std::move(ownedPath)) {}

  int fd_ = -1;
  std::filesystem::path ownedPath_;  // a listening socket's path, removed with it
};

}  // namespace surroundd::daemon
