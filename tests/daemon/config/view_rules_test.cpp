// vehicle_signals.view_rules: read from the config with their mistakes named, and the first rule
// whose every condition holds wins; a condition on an unknown signal never holds.

#include "daemon/config/view_rules.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/daemon/config/config_test_support.hpp"

namespace surroundd::daemon {
namespace {

using vehicle::Gear;
using vehicle::Indicator;

TEST_F(ConfigTest, ViewRulesAreReadWithTheirMistakesNamed) {
  const Config config =
      loadConfig(configWith("capture:",
                            "vehicle_signals:\n  stale_after_s: 0.25\n  view_rules:\n"
                            "    - {gear: R, view: top}\n"
                            "    - {indicator: left, speed_below_kmh: 30, view: split}\n"
                            "    - {speed_above_kmh: 15, view: orbit}\ncapture:"));
  const auto& rules = config.vehicleSignals.viewRules;
  EXPECT_DOUBLE_EQ(config.vehicleSignals.staleAfterS, 0.25);
  ASSERT_EQ(rules.size(), 3u);
  EXPECT_EQ(describe(rules[0]), "gear R -> top");
  EXPECT_EQ(describe(rules[1]), "indicator left, speed below 30 km/h -> split");
  EXPECT_EQ(describe(rules[2]), "speed above 15 km/h -> orbit");
  expectOneError("capture:", "vehicle_signals:\n  view_rules: [{gear: X, view: top}]\ncapture:",
                 {"vehicle_signals.view_rules[0].gear", "expected P, R, N or D"});
  expectOneError("capture:", "vehicle_signals:\n  view_rules: [{view: top}]\ncapture:",
                 {"vehicle_signals.view_rules[0]", "expected a condition"});
  expectOneError("capture:", "vehicle_signals:\n  view_rules: [{gear: R}]\ncapture:",
                 {"vehicle_signals.view_rules[0]", "expected 'view'"});
  expectOneError(
      "capture:", "vehicle_signals:\n  view_rules: [{gear: R, view: sideways}]\ncapture:",
      {"vehicle_signals.view_rules[0].view", "got 'sideways'"});
  expectOneError(
      "capture:", "vehicle_signals:\n  view_rules: [{gear: R, view: top, wipers: on}]\ncapture:",
      {"vehicle_signals.view_rules[0].wipers", "unknown key"});
}

TEST(ViewRules, TheFirstRuleThatHoldsWinsAndUnknownSignalsHoldNoCondition) {
  const std::vector<ViewRule> rules{
      {Gear::kReverse, std::nullopt, std::nullopt, std::nullopt, ViewKind::kTop},
      {std::nullopt, Indicator::kLeft, 30.0, std::nullopt, ViewKind::kSplit},
      {std::nullopt, std::nullopt, std::nullopt, 15.0, ViewKind::kOrbit},
  };
  vehicle::VehicleSignals signals;
  EXPECT_EQ(ruleThatHolds(rules, signals), nullptr);
  signals.gear = Gear::kReverse;
  signals.indicator = Indicator::kLeft;
  signals.speedKmh = 5;
  EXPECT_EQ(ruleThatHolds(rules, signals), &rules[0]);  // first wins
  signals.gear = Gear::kDrive;
  EXPECT_EQ(ruleThatHolds(rules, signals), &rules[1]);
  signals.speedKmh = std::nullopt;  // unknown: "below 30" does not hold
  EXPECT_EQ(ruleThatHolds(rules, signals), nullptr);
  signals.speedKmh = 40;
  EXPECT_EQ(ruleThatHolds(rules, signals), &rules[2]);
  signals.indicator = Indicator::kOff;
  signals.speedKmh = 15;  // strictly above
  EXPECT_EQ(ruleThatHolds(rules, signals), nullptr);
}

}  // namespace
}  // namespace surroundd::daemon
