#pragma once
// The vehicle's signals from its CAN bus: which CAN signal (from a DBC file or written out in the
// config) carries each of gear, steering, speed and indicators, and CanSignalReader, which takes
// the frames waiting on the bus into a VehicleSignalState. A gear or an indicator is a number on
// the bus: the mapping says which numbers mean which.
//
// The bus is opened when the reader is made and again after it fails (an interface that is not
// there yet, or went down): after 1 s, then twice as long each time up to 30 s, each failure
// logged once. Nothing here throws; polling never waits.

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "vehicle/can_bus.hpp"
#include "vehicle/can_database.hpp"
#include "vehicle/vehicle_signals.hpp"

namespace surroundd::vehicle {

struct CanSignalMapping {
  std::string interface;  // e.g. "can0"
  std::optional<CanSignal> gear;
  std::optional<CanSignal> steeringDeg;  // the steering wheel in degrees, positive left
  std::optional<CanSignal> speedKmh;
  std::optional<CanSignal> indicator;
  std::vector<std::pair<double, Gear>> gearValues;  // the gear signal's value for each gear
  std::vector<std::pair<double, Indicator>> indicatorValues;

  bool operator==(const CanSignalMapping&) const = default;
};

class CanSignalReader {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr std::chrono::seconds kFirstRetry{1};
  static constexpr std::chrono::seconds kLastRetry{30};

  CanSignalReader(CanSignalMapping mapping, std::unique_ptr<CanBus> bus, Clock::time_point now);

  // Takes every frame waiting into `state`, each at `now`; opens the bus again when that is due.
  void poll(VehicleSignalState& state, Clock::time_point now);
  // "can0: open, 1520 frames, 3 unreadable (last: ...)", or "can0: down (...), next try in 4 s".
  std::string describe(Clock::time_point now) const;

  std::uint64_t frames() const { return frames_; }
  std::uint64_t unreadable() const { return unreadable_; }

 private:
  void open(Clock::time_point now);
  void failed(const std::string& why, Clock::time_point now);
  // The signals a frame carries; an error names what in it could not be read.
  std::optional<std::string> read(const CanFrame& frame, SignalUpdate& update) const;

  CanSignalMapping mapping_;
  std::unique_ptr<CanBus> bus_;
  bool open_ = false;
  std::string down_;  // why the bus is not open
  Clock::time_point nextTry_{};
  std::chrono::seconds retryDelay_{0};
  std::uint64_t frames_ = 0;
  std::uint64_t unreadable_ = 0;
  std::string lastUnreadable_;
};

}  // namespace surroundd::vehicle
