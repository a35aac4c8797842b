// vehicle_signals.can: CAN signals named in a DBC file or written out in the config, with the
// numbers of gears and indicators, and every mistake named by its key.

#include "daemon/config/can_mapping_yaml.hpp"

#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/daemon/config/config_test_support.hpp"

namespace surroundd::daemon {
namespace {

using vehicle::ByteOrder;
using vehicle::Gear;
using vehicle::Indicator;

const std::string kDbc =
    (std::filesystem::path(SURROUNDD_SOURCE_DIR) / "tests/vehicle/test_vehicle.dbc").string();

std::string canSection(const std::string& body) {
  return "vehicle_signals:\n  can:\n" + body + "capture:";
}

TEST_F(ConfigTest, CanSignalsAreNamedInTheDatabaseOrWrittenOut) {
  const Config config = loadConfig(configWith(
      "capture:", canSection("    interface: vcan0\n    database: " + kDbc +
                             "\n"
                             "    gear: {signal: GearLever, values: {P: 0, R: 1, D: 3}}\n"
                             "    indicator: {signal: TurnIndicator, values: {left: 1, right: 2}}\n"
                             "    steering_deg: {id: 0x25, start_bit: 7, length: 16, byte_order: "
                             "motorola, signed: true, factor: 0.1}\n"
                             "    speed_kmh: {signal: BodyStatus.VehicleSpeed}\n")));
  ASSERT_TRUE(config.vehicleSignals.can);
  const auto& can = *config.vehicleSignals.can;
  EXPECT_EQ(can.interface, "vcan0");
  ASSERT_TRUE(can.gear);
  EXPECT_EQ(can.gear->messageId, 1160u);
  EXPECT_EQ(can.gearValues, (std::vector<std::pair<double, Gear>>{
                                {0, Gear::kPark}, {1, Gear::kReverse}, {3, Gear::kDrive}}));
  EXPECT_EQ(can.indicatorValues, (std::vector<std::pair<double, Indicator>>{
                                     {1, Indicator::kLeft}, {2, Indicator::kRight}}));
  // Written out, it is the signal the DBC file defines.
  ASSERT_TRUE(can.steeringDeg);
  EXPECT_EQ(can.steeringDeg->messageId, 0x25u);
  EXPECT_EQ(can.steeringDeg->order, ByteOrder::kMotorola);
  EXPECT_TRUE(can.steeringDeg->isSigned);
  EXPECT_DOUBLE_EQ(can.steeringDeg->factor, 0.1);
  ASSERT_TRUE(can.speedKmh);
  EXPECT_TRUE(can.speedKmh->extended);
  EXPECT_FALSE(loadConfig(configWith("capture:", "capture:")).vehicleSignals.can);
}

TEST_F(ConfigTest, CanMistakesAreNamedByTheirKey) {
  const std::string database = "    interface: can0\n    database: " + kDbc + "\n";
  expectOneError(
      "capture:", canSection(database + "    speed_kmh: {signal: Speed}\n"),
      {"vehicle_signals.can.speed_kmh.signal", "no signal 'Speed' in", "test_vehicle.dbc"});
  expectOneError("capture:", canSection(database + "    speed_kmh: {signal: GearCounter}\n"),
                 {"vehicle_signals.can.speed_kmh.signal",
                  "is in several messages (Gearbox, Trailer): name it as MESSAGE.SIGNAL"});
  expectOneError("capture:", canSection(database + "    gear: {signal: GearLever}\n"),
                 {"vehicle_signals.can.gear", "missing key 'values'", "P, R, N, D"});
  expectOneError(
      "capture:", canSection(database + "    indicator: {signal: TurnIndicator, values: {}}\n"),
      {"vehicle_signals.can.indicator.values",
       "expected the numbers of off, left, "
       "right, hazard"});
  EXPECT_THAT(errorsOf(configWith("capture:",
                                  canSection(database + "    indicator: {signal: TurnIndicator, "
                                                        "values: {up: 1}}\n"))),
              ::testing::Contains(::testing::HasSubstr(
                  "indicator.values.up: unknown key (expected one of: hazard, left, off, right)")));
  expectOneError("capture:", canSection("    interface: can0\n    speed_kmh: {signal: Speed}\n"),
                 {"vehicle_signals.can.speed_kmh.signal", "'database' is not set"});
  expectOneError("capture:",
                 canSection("    interface: can0\n    database: /nonexistent/car.dbc\n"
                            "    speed_kmh: {id: 1, start_bit: 0, length: 8}\n"),
                 {"vehicle_signals.can.database", "no such file"});
  expectOneError("capture:",
                 canSection("    interface: can0\n    speed_kmh: {id: 0x800, start_bit: 0, "
                            "length: 8}\n"),
                 {"vehicle_signals.can.speed_kmh.id", "expected a 11-bit CAN id, 0..0x7FF",
                  "extended: true for 29-bit ids"});
  expectOneError("capture:",
                 canSection("    interface: can0\n    speed_kmh: {id: 1, start_bit: 508, "
                            "length: 8}\n"),
                 {"vehicle_signals.can.speed_kmh", "run past a 64-byte frame"});
  expectOneError("capture:",
                 canSection("    interface: can0\n    speed_kmh: {id: 1, start_bit: 0, "
                            "length: 8, byte_order: little}\n"),
                 {"vehicle_signals.can.speed_kmh.byte_order", "little"});
  expectOneError("capture:",
                 canSection("    interface: can0/x\n    speed_kmh: {id: 1, start_bit: "
                            "0, length: 8}\n"),
                 {"vehicle_signals.can.interface", "expected a network interface name"});
  expectOneError("capture:", canSection("    interface: can0\n"),
                 {"vehicle_signals.can", "expected the signals it carries"});
  expectOneError("capture:",
                 canSection("    interface: can0\n    speed_kmh: {id: 1, start_bit: 0, length: 8, "
                            "signal: Speed}\n"),
                 {"vehicle_signals.can.speed_kmh", "not both"});
}

}  // namespace
}  // namespace surroundd::daemon
