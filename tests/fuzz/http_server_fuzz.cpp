// Whole requests through the real HTTP output: one HttpStreamSink in this process, each input sent
// as the bytes of one connection (loopback TCP), then the answer read to its end. libmicrohttpd
// parses the request line and headers; the checks (URL and body bounds, Host, Origin) and the
// routing (paths, methods, POST /view's argument) are ours. A crash, UB, or a server that stops
// answering (the probe after each input) is a finding. Slower than the pure targets (a connection
// and a server thread per input), so http_host_fuzz covers the header checks at full speed.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string_view>

#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include "render/outputs/http_stream_sink.hpp"
#include "tests/fuzz/fuzz_support.hpp"

namespace {

surroundd::render::HttpStreamSink& sink() {
  static const auto instance = [] {
    surroundd::render::HttpStreamSettings settings;
    settings.port = 0;
    settings.views = {"top", "360", "orbit", "split"};
    settings.initialView = "top";
    settings.allowedHosts = {"surround.local"};
    auto made = std::make_unique<surroundd::render::HttpStreamSink>(settings);
    // A picture, so that /snapshot.jpg and /stream.mjpg answer with one.
    made->consume(cv::Mat(48, 64, CV_8UC3, cv::Scalar(40, 90, 200)), std::chrono::nanoseconds(0));
    return made;
  }();
  return *instance;
}

// Sends `request` on a new connection, ends the sending side, and reads until the server closes
// or stays silent for 20 ms (a stream never ends by itself: with no new picture it goes quiet after
// its first part, and each stream input costs that wait). The number of bytes answered.
std::size_t exchange(std::string_view request) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) std::abort();
  const timeval silence{0, 20'000};
  const timeval sendTimeout{0, 200'000};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &silence, sizeof silence);
  ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &sendTimeout, sizeof sendTimeout);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(sink().port()));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::size_t answered = 0;
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0) {
    while (!request.empty()) {
      const ssize_t sent = ::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
      if (sent <= 0) break;  // the server closed early (a refused request): fine
      request.remove_prefix(static_cast<std::size_t>(sent));
    }
    ::shutdown(fd, SHUT_WR);
    char buffer[4096];
    ssize_t got = 0;
    while ((got = ::recv(fd, buffer, sizeof buffer, 0)) > 0) {
      answered += static_cast<std::size_t>(got);
      if (answered > (std::size_t{1} << 20)) break;
    }
  }
  ::close(fd);
  return answered;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  surroundd::fuzz::quietLogs();
  (void)sink();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  (void)exchange(surroundd::fuzz::asText(data, size));
  (void)sink().takeViewRequest();
  // The server still answers a plain request after whatever came before. Retried for up to 10 s:
  // the server notices closed connections on their own threads, so under load the connection
  // limits may still count the last few for a moment (a transient refusal, not a dead server).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (exchange("GET /status.json HTTP/1.0\r\n\r\n") == 0) {
    FUZZ_CHECK(std::chrono::steady_clock::now() <= deadline);  // the server answers again
  }
  return 0;
}
