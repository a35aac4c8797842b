#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include "vehicle/can_bus.hpp"

namespace surroundd::vehicle {
namespace {

class SocketCanBus final : public CanBus {
 public:
  ~SocketCanBus() override { close(); }

  int open(const std::string& interface, std::span<const CanId> ids) override {
    close();
    const unsigned index = ::if_nametoindex(interface.c_str());
    if (index == 0) return ENODEV;
    fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (fd_ < 0) return errno;
    // The kernel drops every other frame: the bus may carry thousands a second.
    std::vector<can_filter> filters;
    for (const CanId& id : ids) {
      filters.push_back(id.extended ? can_filter{id.id | CAN_EFF_FLAG, CAN_EFF_MASK | CAN_EFF_FLAG}
                                    : can_filter{id.id, CAN_SFF_MASK | CAN_EFF_FLAG});
    }
    const int enable = 1;
    if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                     static_cast<socklen_t>(filters.size() * sizeof(can_filter))) != 0 ||
        ::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &enable, sizeof(enable)) != 0) {
      return failed();
    }
    sockaddr_can address{};
    address.can_family = AF_CAN;
    address.can_ifindex = static_cast<int>(index);
    // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): the sockets API's own cast
    if (::bind(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
      return failed();
    }
    return 0;
  }

  void close() override {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

  int receive(CanFrame& frame) override {
    canfd_frame raw{};
    ssize_t got = 0;
    do {
      got = ::read(fd_, &raw, sizeof(raw));
    } while (got < 0 && errno == EINTR);
    if (got < 0) return errno == EWOULDBLOCK ? EAGAIN : errno;
    if (got != static_cast<ssize_t>(CAN_MTU) && got != static_cast<ssize_t>(CANFD_MTU)) {
      return EPROTO;
    }
    frame.extended = (raw.can_id & CAN_EFF_FLAG) != 0;
    frame.id = raw.can_id & (frame.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
    frame.length = std::min<std::uint8_t>(raw.len, got == CAN_MTU ? CAN_MAX_DLEN : CANFD_MAX_DLEN);
    std::memcpy(frame.data.data(), raw.data, frame.length);
    return 0;
  }

  int send(const CanFrame& frame) override {
    canfd_frame raw{};
    raw.can_id = frame.id | (frame.extended ? CAN_EFF_FLAG : 0U);
    raw.len = frame.length;
    std::memcpy(raw.data, frame.data.data(), frame.length);
    const std::size_t size = frame.length <= CAN_MAX_DLEN ? CAN_MTU : CANFD_MTU;
    ssize_t sent = 0;
    do {
      sent = ::write(fd_, &raw, size);
    } while (sent < 0 && errno == EINTR);
    if (sent < 0) return errno;
    return sent == static_cast<ssize_t>(size) ? 0 : EIO;
  }

 private:
  int failed() {
    const int error = errno;
    close();
    return error;
  }

  int fd_ = -1;
};

}  // namespace

std::unique_ptr<CanBus> makeSocketCanBus() { return std::make_unique<SocketCanBus>(); }

}  // namespace surroundd::vehicle
