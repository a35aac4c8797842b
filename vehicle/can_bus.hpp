#pragma once
// The only way the CAN code reaches the kernel: one SocketCAN raw socket (PF_CAN, CAN_RAW) on one
// interface, receiving only the frames of the given ids, without waiting. The kernel's
// implementation is makeSocketCanBus(); tests stand an in-process fake in its place, and one test
// uses a `vcan` interface where the machine has one.
//
// Every call returns 0 on success or an errno value (never throws), as the kernel does.

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

namespace surroundd::vehicle {

// One frame's id and payload: classic CAN (up to 8 bytes) or CAN FD (up to 64).
struct CanFrame {
  std::uint32_t id = 0;  // 11 bits, or 29 with `extended`
  bool extended = false;
  std::uint8_t length = 0;
  std::array<std::uint8_t, 64> data{};

  std::span<const std::uint8_t> payload() const { return {data.data(), length}; }
};

// A frame id to receive.
struct CanId {
  std::uint32_t id = 0;
  bool extended = false;
};

class CanBus {
 public:
  virtual ~CanBus() = default;
  CanBus() = default;
  CanBus(const CanBus&) = delete;
  CanBus& operator=(const CanBus&) = delete;

  // Opens the interface (e.g. "can0"), receiving frames of `ids` alone, CAN FD ones included:
  // ENODEV when there is no such interface.
  virtual int open(const std::string& interface, std::span<const CanId> ids) = 0;
  virtual void close() = 0;
  // The next frame received, without waiting: 0 with `frame` filled, EAGAIN when none waits, or
  // the error (ENETDOWN: the interface went down).
  virtual int receive(CanFrame& frame) = 0;
  // Sends one frame (for a vehicle's part on a bus: a bench, the tests).
  virtual int send(const CanFrame& frame) = 0;
};

std::unique_ptr<CanBus> makeSocketCanBus();

}  // namespace surroundd::vehicle
