// The vehicle's signals as the control socket gives them: each item checked before any is taken,
// and each signal back at its safe default once it has not been renewed for the stale time.

#include "vehicle/vehicle_signals.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace surroundd::vehicle {
namespace {

using std::chrono::milliseconds;
using ::testing::HasSubstr;
using Clock = VehicleSignalState::Clock;

TEST(VehicleSignals, ItemsAreTakenInAnyOrderAndReadBack) {
  VehicleSignalState state(milliseconds(500));
  const auto t0 = Clock::now();
  EXPECT_EQ(state.at(t0), VehicleSignals{});  // nothing said yet: every default
  EXPECT_EQ(state.set("speed_kmh=3.5  gear=r indicator=left steering_deg=-12.5", t0), std::nullopt);
  const VehicleSignals signals = state.at(t0 + milliseconds(100));
  EXPECT_EQ(signals.gear, Gear::kReverse);
  EXPECT_DOUBLE_EQ(signals.steeringDeg, -12.5);
  ASSERT_TRUE(signals.speedKmh);
  EXPECT_DOUBLE_EQ(*signals.speedKmh, 3.5);
  EXPECT_EQ(signals.indicator, Indicator::kLeft);
  EXPECT_EQ(state.describe(t0 + milliseconds(100)),
            "gear R, steering -12.5 deg, speed 3.5 km/h, indicator left");
}

// What a lost source last said (reverse, an indicator) must not stay in force.
TEST(VehicleSignals, ASignalNotRenewedGoesBackToItsSafeDefault) {
  VehicleSignalState state(milliseconds(500));
  const auto t0 = Clock::now();
  ASSERT_EQ(state.set("gear=R speed_kmh=4 indicator=right steering_deg=90", t0), std::nullopt);
  ASSERT_EQ(state.set("gear=R", t0 + milliseconds(400)), std::nullopt);  // only the gear renewed
  const VehicleSignals later = state.at(t0 + milliseconds(700));
  EXPECT_EQ(later.gear, Gear::kReverse);
  EXPECT_EQ(later.speedKmh, std::nullopt);
  EXPECT_EQ(later.indicator, Indicator::kOff);
  EXPECT_DOUBLE_EQ(later.steeringDeg, 0.0);
  EXPECT_EQ(state.describe(t0 + milliseconds(700)),
            "gear R, steering 90.0 deg (stale), speed 4.0 km/h (stale), indicator right (stale)");
  EXPECT_EQ(state.at(t0 + milliseconds(900)), VehicleSignals{});
  EXPECT_THAT(VehicleSignalState(milliseconds(500)).describe(t0), HasSubstr("gear unknown (none)"));
}

TEST(VehicleSignals, ALineWithABadItemNamesItAndChangesNothing) {
  VehicleSignalState state(milliseconds(500));
  const auto t0 = Clock::now();
  ASSERT_EQ(state.set("gear=D speed_kmh=20", t0), std::nullopt);
  const auto refused = [&](const char* line, const char* why) {
    const auto error = state.set(line, t0);
    ASSERT_TRUE(error) << line;
    EXPECT_THAT(*error, HasSubstr(why)) << line;
  };
  refused("gear=R speed_kmh=fast", "speed_kmh: expected km/h in 0..500, got 'fast'");
  refused("gear=X", "gear: expected P, R, N or D, got 'X'");
  refused("gear=R speed_kmh=-1", "speed_kmh");
  refused("steering_deg=2000", "steering_deg: expected degrees in -1080..1080");
  refused("steering_deg=nan", "steering_deg");
  refused("indicator=up", "indicator: expected off, left, right or hazard");
  refused("gear=R wipers=on", "unknown signal 'wipers'");
  refused("gear R", "'gear': expected NAME=VALUE");
  refused("   ", "expected NAME=VALUE items");
  const VehicleSignals unchanged = state.at(t0);
  EXPECT_EQ(unchanged.gear, Gear::kDrive);
  EXPECT_EQ(unchanged.speedKmh, 20.0);
}

}  // namespace
}  // namespace surroundd::vehicle
