#include "vehicle/can_signal_reader.hpp"

#include <algorithm>
#include <cmath>
#include <system_error>
#include <vector>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace surroundd::vehicle {
namespace {

// Frames taken per poll at most: the kernel's filter passes only the mapped messages, a few
// hundred a second at most, so this bounds a poll's time without ever leaving frames behind.
constexpr int kFramesPerPoll = 1000;

bool carries(const CanSignal& signal, const CanFrame& frame) {
  return signal.messageId == frame.id && signal.extended == frame.extended;
}

// The entry of `values` whose number the decoded value is, to within half a raw step.
template <class T>
std::optional<T> lookUp(const std::vector<std::pair<double, T>>& values, const CanSignal& signal,
                        double value) {
  for (const auto& [number, meaning] : values) {
    if (std::abs(number - value) < std::abs(signal.factor) / 2) return meaning;
  }
  return std::nullopt;
}

}  // namespace

CanSignalReader::CanSignalReader(CanSignalMapping mapping, std::unique_ptr<CanBus> bus,
                                 Clock::time_point now)
    : mapping_(std::move(mapping)), bus_(std::move(bus)) {
  open(now);
}

void CanSignalReader::open(Clock::time_point now) {
  std::vector<CanId> ids;
  for (const auto* signal :
       {&mapping_.gear, &mapping_.steeringDeg, &mapping_.speedKmh, &mapping_.indicator}) {
    if (!*signal) continue;
    const CanId id{(*signal)->messageId, (*signal)->extended};
    const bool known = std::ranges::any_of(ids, [&](const CanId& other) {
      return other.id == id.id && other.extended == id.extended;
    });
    if (!known) ids.push_back(id);
  }
  if (const int error = bus_->open(mapping_.interface, ids); error != 0) {
    failed(fmt::format("cannot open it: {}", std::system_category().message(error)), now);
    return;
  }
  if (!down_.empty()) spdlog::info("vehicle signals: CAN {} is open again", mapping_.interface);
  open_ = true;
  down_.clear();
  retryDelay_ = std::chrono::seconds(0);
}

void CanSignalReader::failed(const std::string& why, Clock::time_point now) {
  bus_->close();
  open_ = false;
  retryDelay_ = std::clamp(retryDelay_ * 2, kFirstRetry, kLastRetry);
  nextTry_ = now + retryDelay_;
  // Once per outage: the retries of an interface that stays away say nothing new.
  if (down_.empty()) {
    spdlog::warn(
        "vehicle signals: CAN {}: {}; the signals it carries go stale, trying again "
        "in {} s and then less often",
        mapping_.interface, why, retryDelay_.count());
  }
  down_ = why;
}

void CanSignalReader::poll(VehicleSignalState& state, Clock::time_point now) {
  if (!open_) {
    if (now < nextTry_) return;
    open(now);
    if (!open_) return;
  }
  for (int k = 0; k < kFramesPerPoll; ++k) {
    CanFrame frame;
    const int error = bus_->receive(frame);
    if (error == EAGAIN) return;
    if (error != 0) {
      failed(fmt::format("receiving: {}", std::system_category().message(error)), now);
      return;
    }
    ++frames_;
    SignalUpdate update;
    if (auto problem = read(frame, update)) {
      if (unreadable_ == 0) {
        spdlog::warn("vehicle signals: CAN {}: {} (counted in the status from now on)",
                     mapping_.interface, *problem);
      }
      ++unreadable_;
      lastUnreadable_ = std::move(*problem);
    }
    state.apply(update, now);
  }
}

std::optional<std::string> CanSignalReader::read(const CanFrame& frame,
                                                 SignalUpdate& update) const {
  std::optional<std::string> problem;
  const auto value = [&](const CanSignal& signal) -> std::optional<double> {
    const auto decoded = signal.decode(frame.payload());
    if (!decoded) {
      problem = fmt::format("frame 0x{:X} of {} bytes is too short for '{}'", frame.id,
                            frame.length, signal.name);
    }
    return decoded;
  };
  if (mapping_.gear && carries(*mapping_.gear, frame)) {
    // A number the mapping does not name ("invalid", "not available") reads as an unknown gear.
    if (const auto v = value(*mapping_.gear)) {
      update.gear = lookUp(mapping_.gearValues, *mapping_.gear, *v).value_or(Gear::kUnknown);
    }
  }
  if (mapping_.indicator && carries(*mapping_.indicator, frame)) {
    if (const auto v = value(*mapping_.indicator)) {
      update.indicator =
          lookUp(mapping_.indicatorValues, *mapping_.indicator, *v).value_or(Indicator::kOff);
    }
  }
  if (mapping_.steeringDeg && carries(*mapping_.steeringDeg, frame)) {
    update.steeringDeg = value(*mapping_.steeringDeg);
  }
  if (mapping_.speedKmh && carries(*mapping_.speedKmh, frame)) {
    update.speedKmh = value(*mapping_.speedKmh);
  }
  // An implausible number (a signal mapped to the wrong message, a sensor's error code) is not
  // taken; the frame's other signals are.
  if (auto why = implausible({std::nullopt, update.steeringDeg, std::nullopt, std::nullopt})) {
    update.steeringDeg.reset();
    problem = fmt::format("frame 0x{:X}: {}", frame.id, *why);
  }
  if (auto why = implausible({std::nullopt, std::nullopt, update.speedKmh, std::nullopt})) {
    update.speedKmh.reset();
    problem = fmt::format("frame 0x{:X}: {}", frame.id, *why);
  }
  return problem;
}

std::string CanSignalReader::describe(Clock::time_point now) const {
  if (!open_) {
    const auto wait =
        std::chrono::ceil<std::chrono::seconds>(std::max(nextTry_ - now, Clock::duration(0)));
    return fmt::format("CAN {}: down ({}), next try in {} s", mapping_.interface, down_,
                       wait.count());
  }
  if (unreadable_ == 0) return fmt::format("CAN {}: open, {} frames", mapping_.interface, frames_);
  return fmt::format("CAN {}: open, {} frames, {} unreadable (last: {})", mapping_.interface,
                     frames_, unreadable_, lastUnreadable_);
}

}  // namespace surroundd::vehicle
