#include "vehicle/vehicle_signals.hpp"

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <vector>

#include <fmt/format.h>

namespace surroundd::vehicle {
namespace {

constexpr std::array<std::pair<Gear, const char*>, 5> kGears{{{Gear::kUnknown, "unknown"},
                                                              {Gear::kPark, "P"},
                                                              {Gear::kReverse, "R"},
                                                              {Gear::kNeutral, "N"},
                                                              {Gear::kDrive, "D"}}};
constexpr std::array<std::pair<Indicator, const char*>, 4> kIndicators{
    {{Indicator::kOff, "off"},
     {Indicator::kLeft, "left"},
     {Indicator::kRight, "right"},
     {Indicator::kHazard, "hazard"}}};

std::optional<double> number(std::string_view text) {
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

}  // namespace

const char* toString(Gear gear) {
  for (const auto& [g, name] : kGears) {
    if (g == gear) return name;
  }
  return "?";
}

const char* toString(Indicator indicator) {
  for (const auto& [i, name] : kIndicators) {
    if (i == indicator) return name;
  }
  return "?";
}

std::optional<Gear> parseGear(std::string_view text) {
  if (text.size() != 1) return std::nullopt;
  const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(text[0])));
  for (const auto& [gear, name] : kGears) {
    if (gear != Gear::kUnknown && name[0] == letter) return gear;
  }
  return std::nullopt;
}

std::optional<Indicator> parseIndicator(std::string_view text) {
  for (const auto& [indicator, name] : kIndicators) {
    if (text == name) return indicator;
  }
  return std::nullopt;
}

std::optional<std::string> implausible(const SignalUpdate& update) {
  if (update.steeringDeg && !(std::abs(*update.steeringDeg) <= 1080)) {
    return fmt::format("steering_deg: expected degrees in -1080..1080, got {:g}",
                       *update.steeringDeg);
  }
  if (update.speedKmh && !(*update.speedKmh >= 0 && *update.speedKmh <= 500)) {
    return fmt::format("speed_kmh: expected km/h in 0..500, got {:g}", *update.speedKmh);
  }
  return std::nullopt;
}

std::optional<std::string> VehicleSignalState::set(std::string_view assignments,
                                                   Clock::time_point now) {
  // Checked whole first, then taken: a line with one bad item changes nothing.
  SignalUpdate change;
  std::size_t items = 0;
  std::size_t at = 0;
  while (at < assignments.size()) {
    if (assignments[at] == ' ') {
      ++at;
      continue;
    }
    const std::size_t end = std::min(assignments.find(' ', at), assignments.size());
    const std::string_view item = assignments.substr(at, end - at);
    at = end;
    ++items;
    const std::size_t equals = item.find('=');
    if (equals == std::string_view::npos) {
      return fmt::format("'{}': expected NAME=VALUE (gear, steering_deg, speed_kmh, indicator)",
                         item);
    }
    const std::string_view name = item.substr(0, equals);
    const std::string_view value = item.substr(equals + 1);
    if (name == "gear") {
      change.gear = parseGear(value);
      if (!change.gear) return fmt::format("gear: expected P, R, N or D, got '{}'", value);
    } else if (name == "steering_deg") {
      change.steeringDeg = number(value);
      if (!change.steeringDeg) {
        return fmt::format("steering_deg: expected degrees in -1080..1080, got '{}'", value);
      }
    } else if (name == "speed_kmh") {
      change.speedKmh = number(value);
      if (!change.speedKmh)
        return fmt::format("speed_kmh: expected km/h in 0..500, got '{}'", value);
    } else if (name == "indicator") {
      change.indicator = parseIndicator(value);
      if (!change.indicator) {
        return fmt::format("indicator: expected off, left, right or hazard, got '{}'", value);
      }
    } else {
      return fmt::format("unknown signal '{}' (gear, steering_deg, speed_kmh, indicator)", name);
    }
  }
  if (items == 0)
    return std::string("expected NAME=VALUE items (gear, steering_deg, speed_kmh, indicator)");
  if (auto problem = implausible(change)) return problem;
  apply(change, now);
  return std::nullopt;
}

void VehicleSignalState::apply(const SignalUpdate& update, Clock::time_point now) {
  if (update.gear) gear_ = {*update.gear, now};
  if (update.steeringDeg) steeringDeg_ = {*update.steeringDeg, now};
  if (update.speedKmh) speedKmh_ = {*update.speedKmh, now};
  if (update.indicator) indicator_ = {*update.indicator, now};
}

VehicleSignals VehicleSignalState::at(Clock::time_point now) const {
  VehicleSignals signals;
  if (fresh(gear_, now)) signals.gear = gear_.value;
  if (fresh(steeringDeg_, now)) signals.steeringDeg = steeringDeg_.value;
  if (fresh(speedKmh_, now)) signals.speedKmh = speedKmh_.value;
  if (fresh(indicator_, now)) signals.indicator = indicator_.value;
  return signals;
}

std::string VehicleSignalState::describe(Clock::time_point now) const {
  const auto mark = [&](const auto& held) -> std::string {
    if (!held.at) return " (none)";
    return fresh(held, now) ? "" : " (stale)";
  };
  return fmt::format("gear {}{}, steering {:.1f} deg{}, speed {:.1f} km/h{}, indicator {}{}",
                     toString(gear_.value), mark(gear_), steeringDeg_.value, mark(steeringDeg_),
                     speedKmh_.value, mark(speedKmh_), toString(indicator_.value),
                     mark(indicator_));
}

}  // namespace surroundd::vehicle
