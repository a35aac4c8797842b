#pragma once
// An in-process CAN bus in the kernel's place (vehicle/can_bus.hpp): the test queues the frames
// the vehicle sends and the errors the kernel gives, and sees what the reader asked for. The
// test keeps the shared state; the reader owns the bus.

#include <cerrno>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "vehicle/can_bus.hpp"

namespace surroundd::testing {

using vehicle::CanBus;
using vehicle::CanFrame;
using vehicle::CanId;

struct FakeCanBusState {
  std::deque<CanFrame> frames;  // waiting to be received
  int openError = 0;            // what the next open() returns
  int receiveError = 0;         // returned by receive() once, instead of a frame
  int opens = 0;
  bool open = false;
  std::string interface;
  std::vector<CanId> ids;
  std::vector<CanFrame> sent;
};

class FakeCanBus final : public CanBus {
 public:
  explicit FakeCanBus(std::shared_ptr<FakeCanBusState> state) : state_(std::move(state)) {}

  int open(const std::string& interface, std::span<const CanId> ids) override {
    ++state_->opens;
    state_->interface = interface;
    state_->ids.assign(ids.begin(), ids.end());
    state_->open = state_->openError == 0;
    return state_->openError;
  }
  void close() override { state_->open = false; }
  int receive(CanFrame& frame) override {
    if (!state_->open) return EBADF;
    if (const int error = std::exchange(state_->receiveError, 0); error != 0) return error;
    if (state_->frames.empty()) return EAGAIN;
    frame = state_->frames.front();
    state_->frames.pop_front();
    return 0;
  }
  int send(const CanFrame& frame) override {
    if (!state_->open) return EBADF;
    state_->sent.push_back(frame);
    return 0;
  }

 private:
  std::shared_ptr<FakeCanBusState> state_;
};

}  // namespace surroundd::testing
