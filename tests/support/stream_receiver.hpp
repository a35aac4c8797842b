#pragma once
// Receives a stream (MPEG-TS over UDP, RTSP) with FFmpeg and decodes every picture to BGR, on a
// thread of its own, the way a viewer on the network would (bench::StreamViewer). For UDP,
// listening starts in the constructor, so a sender started afterwards loses nothing; reading ends
// at the stream's end or when nothing has come for `idle`.

#include <atomic>
#include <chrono>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <netinet/in.h>
#include <opencv2/core.hpp>
#include <sys/socket.h>
#include <unistd.h>

#include "tools/bench/stream_viewer.hpp"

namespace surroundd::testing {

// A UDP port nothing listens on right now.
inline int freeUdpPort() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address));
  socklen_t length = sizeof(address);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  ::close(fd);
  return ntohs(address.sin_port);
}

// Whether a UDP socket of this machine is bound to `port` (any address): /proc/net/udp lists each
// as "sl local_address:PORT ...", the port in hexadecimal.
inline bool udpPortBound(int port) {
  std::ifstream table("/proc/net/udp");
  const std::string suffix = fmt::format(":{:04X}", port);
  std::string line;
  std::getline(table, line);  // the header
  while (std::getline(table, line)) {
    std::istringstream fields(line);
    std::string slot;
    std::string localAddress;
    fields >> slot >> localAddress;
    if (localAddress.ends_with(suffix)) return true;
  }
  return false;
}

class StreamReceiver {
 public:
  // MPEG-TS on UDP `port` of this machine.
  StreamReceiver(int port, std::chrono::seconds idle)
      : StreamReceiver({fmt::format("udp://127.0.0.1:{}", port), "udp", idle}) {
    // The viewer binds before it blocks on the first datagram: once the port is bound, nothing
    // the sender sends is lost. Bounded, so a receiver that never binds fails the test.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (!udpPortBound(port)) {
      if (std::chrono::steady_clock::now() > deadline) {
        throw std::runtime_error(fmt::format("the stream receiver never bound UDP port {}", port));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  // Any stream bench::StreamViewer takes (RTSP: it connects, and its PLAY waits for pictures).
  explicit StreamReceiver(bench::StreamViewerSettings settings)
      : ready_([this, settings] { receive(settings); }) {}

  // Waits for the stream to end; the decoded pictures in order.
  std::vector<bench::ViewedPicture> pictures() {
    if (ready_.joinable()) ready_.join();
    return pictures_;
  }
  // Whether the viewer has connected (RTSP: PLAY answered) or failed.
  bool started() const { return started_; }
  // Why nothing or less came; after pictures().
  const std::string& error() const { return error_; }

 private:
  void receive(const bench::StreamViewerSettings& settings) {
    try {
      bench::StreamViewer viewer(settings);
      started_ = true;
      while (auto picture = viewer.next()) pictures_.push_back(std::move(*picture));
    } catch (const std::exception& e) {
      error_ = e.what();
      started_ = true;
    }
  }

  std::vector<bench::ViewedPicture> pictures_;
  std::string error_;
  std::atomic<bool> started_{false};
  std::jthread ready_;  // last: it starts once the members above exist
};

}  // namespace surroundd::testing
