#include "daemon/config/view_rules.hpp"

#include <array>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "daemon/config/can_mapping_yaml.hpp"

namespace surroundd::daemon {
namespace {

constexpr NumberRange kSpeed{0.0, 500.0, false, "km/h"};

// One rule: its conditions (at least one) and its view.
ViewRule readRule(YamlObject& item) {
  ViewRule rule;
  if (item.has("gear")) {
    const std::string text = item.string("gear", "");
    rule.gear = vehicle::parseGear(text);
    if (!rule.gear) item.error("gear", fmt::format("expected P, R, N or D, got '{}'", text));
  }
  if (item.has("indicator")) {
    rule.indicator = item.choice("indicator", vehicle::Indicator::kOff,
                                 {{"off", vehicle::Indicator::kOff},
                                  {"left", vehicle::Indicator::kLeft},
                                  {"right", vehicle::Indicator::kRight},
                                  {"hazard", vehicle::Indicator::kHazard}});
  }
  if (item.has("speed_below_kmh"))
    rule.speedBelowKmh = item.requiredNumber("speed_below_kmh", kSpeed);
  if (item.has("speed_above_kmh"))
    rule.speedAboveKmh = item.requiredNumber("speed_above_kmh", kSpeed);
  const bool conditioned = item.has("gear") || item.has("indicator") ||
                           item.has("speed_below_kmh") || item.has("speed_above_kmh");
  if (!conditioned) {
    item.errorHere("expected a condition: gear, indicator, speed_below_kmh and/or speed_above_kmh");
  }
  if (item.has("view")) {
    rule.view =
        item.choice("view", ViewKind::kTop,
                    std::span<const std::pair<std::string_view, ViewKind>>(render::kViewNames));
  } else {
    item.errorHere(fmt::format("expected 'view': the view the rule brings up ({})",
                               render::viewNameList(", ")));
  }
  item.finish();
  return rule;
}

void readRules(YamlObject& section, VehicleSignalsConfig& c) {
  for (auto& item : section.objectList("view_rules", 0, 32)) c.viewRules.push_back(readRule(item));
}

}  // namespace

const ConfigKeys<VehicleSignalsConfig>& vehicleSignalsKeys() {
  using Key = ConfigKey<VehicleSignalsConfig>;
  static const ConfigKeys<VehicleSignalsConfig> kKeys{
      Key::number("stale_after_s", &VehicleSignalsConfig::staleAfterS,
                  {0.05, 60.0, false, "seconds"},
                  "a signal not renewed for this long reads as its safe default (gear and speed "
                  "unknown, steering straight, indicators off)"),
      Key::custom(
          "view_rules",
          "the views the signals bring up, the first that holds winning; none holding: the "
          "view chosen last by hand. Each: conditions (gear: P|R|N|D, indicator: "
          "off|left|right|hazard, speed_below_kmh, speed_above_kmh; all must hold, an unknown "
          "signal holds none) and view: top|360|orbit|split|rear",
          readRules,
          [](const VehicleSignalsConfig& a, const VehicleSignalsConfig& b) {
            return a.viewRules == b.viewRules;
          },
          {}, Shown::kExample),
      Key::custom(
          "can",
          "the signals from the vehicle's CAN bus (SocketCAN): interface, database (a DBC "
          "file), and gear, steering_deg, speed_kmh, indicator each as {signal: NAME in the "
          "database} or written out {id, extended, start_bit, length, byte_order: "
          "intel|motorola, signed, factor, offset}; gear and indicator with values: {R: 2, ...}",
          readCanMapping,
          [](const VehicleSignalsConfig& a, const VehicleSignalsConfig& b) {
            return a.can == b.can;
          },
          {}, Shown::kExample),
  };
  return kKeys;
}

const ViewRule* ruleThatHolds(std::span<const ViewRule> rules,
                              const vehicle::VehicleSignals& signals) {
  for (const ViewRule& rule : rules) {
    if (rule.gear && signals.gear != *rule.gear) continue;
    if (rule.indicator && signals.indicator != *rule.indicator) continue;
    if (rule.speedBelowKmh && !(signals.speedKmh && *signals.speedKmh < *rule.speedBelowKmh)) {
      continue;
    }
    if (rule.speedAboveKmh && !(signals.speedKmh && *signals.speedKmh > *rule.speedAboveKmh)) {
      continue;
    }
    return &rule;
  }
  return nullptr;
}

std::string describe(const ViewRule& rule) {
  std::vector<std::string> conditions;
  if (rule.gear) conditions.push_back(fmt::format("gear {}", vehicle::toString(*rule.gear)));
  if (rule.indicator) {
    conditions.push_back(fmt::format("indicator {}", vehicle::toString(*rule.indicator)));
  }
  if (rule.speedBelowKmh)
    conditions.push_back(fmt::format("speed below {:g} km/h", *rule.speedBelowKmh));
  if (rule.speedAboveKmh)
    conditions.push_back(fmt::format("speed above {:g} km/h", *rule.speedAboveKmh));
  return fmt::format("{} -> {}", fmt::join(conditions, ", "), toString(rule.view));
}

}  // namespace surroundd::daemon
