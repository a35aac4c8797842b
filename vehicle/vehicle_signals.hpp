#pragma once
// The vehicle's signals as surroundd uses them (gear, steering-wheel angle, speed, turn
// indicators) and VehicleSignalState, which holds the newest value of each with the time it came.
// A signal that has not come for `staleAfter` reads as its safe default — gear and speed unknown,
// steering straight, indicators off — so that nothing a lost source last said (reverse, say)
// stays in force.
//
// Values come as text, "gear=R steering_deg=-12.5 speed_kmh=3 indicator=left" (any of them, in
// any order), from the control socket (`surroundctl signal ...`) for vehicles whose signals come
// from other software. Errors: set() returns a message naming the bad item and takes none of the
// line; nothing throws.

#include <chrono>
#include <optional>
#include <string>
#include <string_view>

namespace surroundd::vehicle {

enum class Gear { kUnknown, kPark, kReverse, kNeutral, kDrive };
enum class Indicator { kOff, kLeft, kRight, kHazard };

const char* toString(Gear gear);            // "unknown", "P", "R", "N", "D"
const char* toString(Indicator indicator);  // "off", "left", "right", "hazard"
// Gears by their letter, upper or lower case; indicators by their name.
std::optional<Gear> parseGear(std::string_view text);
std::optional<Indicator> parseIndicator(std::string_view text);

struct VehicleSignals {
  Gear gear = Gear::kUnknown;
  double steeringDeg = 0;          // the steering wheel, positive turning left
  std::optional<double> speedKmh;  // none: unknown
  Indicator indicator = Indicator::kOff;

  bool operator==(const VehicleSignals&) const = default;
};

// Some of the signals, as one source gave them at once.
struct SignalUpdate {
  std::optional<Gear> gear;
  std::optional<double> steeringDeg;
  std::optional<double> speedKmh;
  std::optional<Indicator> indicator;
};
// Why an update cannot be true (steering beyond ±1080°, speed outside 0..500 km/h); none if it
// can.
std::optional<std::string> implausible(const SignalUpdate& update);

class VehicleSignalState {
 public:
  using Clock = std::chrono::steady_clock;

  explicit VehicleSignalState(Clock::duration staleAfter) : staleAfter_(staleAfter) {}
  void setStaleAfter(Clock::duration staleAfter) { staleAfter_ = staleAfter; }

  // Takes every assignment of the line, or none of them: the message names the first bad one.
  std::optional<std::string> set(std::string_view assignments, Clock::time_point now);
  // Takes the signals the update has (checked by its source: implausible()).
  void apply(const SignalUpdate& update, Clock::time_point now);

  // Each signal as it is now: stale or never set ones at their safe default.
  VehicleSignals at(Clock::time_point now) const;
  // "gear R, steering -12.5 deg, speed 3.0 km/h, indicator left", each stale one marked
  // "(stale)" and one never set "(none)"; for the status.
  std::string describe(Clock::time_point now) const;

 private:
  template <class T>
  struct Held {
    T value{};
    std::optional<Clock::time_point> at;  // when it came; none: never
  };
  template <class T>
  bool fresh(const Held<T>& held, Clock::time_point now) const {
    return held.at && now - *held.at < staleAfter_;
  }

  Clock::duration staleAfter_;
  Held<Gear> gear_;
  Held<double> steeringDeg_;
  Held<double> speedKmh_;
  Held<Indicator> indicator_;
};

}  // namespace surroundd::vehicle
