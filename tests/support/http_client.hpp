#pragma once
// A tiny blocking HTTP/1.0 client over loopback TCP, for tests of servers in this process: send a
// request as written, read the answer (whole, or piece by piece for a stream). Every read gives up
// after 5 s, so a server that hangs fails the test instead of hanging it.

#include <array>
#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

namespace surroundd::testing {

struct HttpResponse {
  int status = 0;       // 0 if the answer had no status line
  std::string headers;  // the header lines, as sent
  std::string body;
};

class HttpConnection {
 public:
  explicit HttpConnection(int port) : fd_(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0)) {
    if (fd_ < 0) fail("socket");
    const timeval timeout{5, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
    ::setsockopt(fd_, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof timeout);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<std::uint16_t>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
      fail("connect");
    }
  }
  ~HttpConnection() { ::close(fd_); }
  HttpConnection(const HttpConnection&) = delete;
  HttpConnection& operator=(const HttpConnection&) = delete;

  void send(std::string_view bytes) {
    while (!bytes.empty()) {
      const ssize_t sent = ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL);
      if (sent < 0) fail("send");
      bytes.remove_prefix(static_cast<std::size_t>(sent));
    }
  }

  // Up to and including `delimiter`; nullopt if the connection ends first.
  std::optional<std::string> readUntil(std::string_view delimiter) {
    std::size_t found = 0;
    while ((found = buffer_.find(delimiter)) == std::string::npos) {
      if (!fill()) return std::nullopt;
    }
    return take(found + delimiter.size());
  }
  // Exactly `count` bytes; nullopt if the connection ends first.
  std::optional<std::string> readExactly(std::size_t count) {
    while (buffer_.size() < count) {
      if (!fill()) return std::nullopt;
    }
    return take(count);
  }
  std::string readToEnd() {
    while (fill()) {
    }
    return take(buffer_.size());
  }

  // The status line and headers of an answer, for reading a streamed body after them.
  HttpResponse readHead() {
    HttpResponse response;
    const std::optional<std::string> head = readUntil("\r\n\r\n");
    if (!head) return response;
    const std::size_t lineEnd = head->find("\r\n");
    const std::size_t space = head->find(' ');
    if (head->starts_with("HTTP/") && space < lineEnd) {
      response.status = std::stoi(head->substr(space + 1, 3));
    }
    response.headers = head->substr(lineEnd + 2);
    return response;
  }

 private:
  // False at the end of the stream (or a 5 s timeout, or a reset).
  bool fill() {
    std::array<char, 16384> chunk{};
    const ssize_t received = ::recv(fd_, chunk.data(), chunk.size(), 0);
    if (received <= 0) return false;
    buffer_.append(chunk.data(), static_cast<std::size_t>(received));
    return true;
  }
  std::string take(std::size_t count) {
    std::string taken = buffer_.substr(0, count);
    buffer_.erase(0, count);
    return taken;
  }
  [[noreturn]] static void fail(const char* what) {
    throw std::system_error(errno, std::generic_category(),
                            std::string("test HTTP client: ") + what);
  }

  int fd_;
  std::string buffer_;
};

// Sends `request` (a whole HTTP/1.0 request, so the server closes after answering) and reads the
// answer to the end.
inline HttpResponse httpExchange(int port, std::string_view request) {
  HttpConnection connection(port);
  connection.send(request);
  HttpResponse response = connection.readHead();
  response.body = connection.readToEnd();
  return response;
}

inline HttpResponse httpRequest(int port, std::string_view method, std::string_view target) {
  return httpExchange(port, std::string(method) + " " + std::string(target) +
                                " HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n");
}

}  // namespace surroundd::testing
