// The vehicle's signals from CAN frames: the test DBC's messages sent on an in-process bus
// (fake_can_bus.hpp), a bus that fails and comes back, and — where the machine has a vcan
// interface — the same through the kernel's SocketCAN.

#include "vehicle/can_signal_reader.hpp"

#include <array>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <net/if.h>

#include "tests/support/log_capture.hpp"
#include "tests/vehicle/fake_can_bus.hpp"

namespace surroundd::vehicle {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;
using Clock = CanSignalReader::Clock;

CanDatabase testDatabase() {
  std::ifstream file(std::filesystem::path(SURROUNDD_SOURCE_DIR) /
                     "tests/vehicle/test_vehicle.dbc");
  return CanDatabase::fromDbc(std::string{std::istreambuf_iterator<char>(file), {}},
                              "test_vehicle.dbc");
}

CanSignalMapping testMapping(const std::string& interface) {
  const CanDatabase database = testDatabase();
  CanSignalMapping mapping;
  mapping.interface = interface;
  mapping.gear = *database.find("GearLever");
  mapping.steeringDeg = *database.find("SteeringWheelAngle");
  mapping.speedKmh = *database.find("VehicleSpeed");
  mapping.indicator = *database.find("TurnIndicator");
  mapping.gearValues = {
      {0, Gear::kPark}, {1, Gear::kReverse}, {2, Gear::kNeutral}, {3, Gear::kDrive}};
  mapping.indicatorValues = {
      {0, Indicator::kOff}, {1, Indicator::kLeft}, {2, Indicator::kRight}, {3, Indicator::kHazard}};
  return mapping;
}

// A frame of `signal`'s message, 8 bytes, with `value` written in.
CanFrame frameWith(const CanSignal& signal, double value, CanFrame frame = {}) {
  frame.id = signal.messageId;
  frame.extended = signal.extended;
  frame.length = 8;
  signal.encode(value, std::span(frame.data).first(8));
  return frame;
}

class CanSignalReaderTest : public ::testing::Test {
 protected:
  std::unique_ptr<CanSignalReader> reader(const std::string& interface = "can0") {
    mapping_ = testMapping(interface);
    return std::make_unique<CanSignalReader>(mapping_, std::make_unique<testing::FakeCanBus>(bus_),
                                             t0_);
  }

  std::shared_ptr<testing::FakeCanBusState> bus_ = std::make_shared<testing::FakeCanBusState>();
  CanSignalMapping mapping_;
  const Clock::time_point t0_ = Clock::now();
  VehicleSignalState signals_{1s};
};

TEST_F(CanSignalReaderTest, FramesOfTheMappedMessagesBecomeTheVehiclesSignals) {
  auto can = reader();
  // One filter per message: speed and indicator share theirs, a 29-bit one.
  EXPECT_EQ(bus_->opens, 1);
  EXPECT_EQ(bus_->interface, "can0");
  ASSERT_EQ(bus_->ids.size(), 3u);
  EXPECT_EQ(bus_->ids[0].id, 1160u);
  EXPECT_EQ(bus_->ids[1].id, 37u);
  EXPECT_EQ(bus_->ids[2].id, 0x18FEF115u);
  EXPECT_TRUE(bus_->ids[2].extended);

  bus_->frames.push_back(frameWith(*mapping_.gear, 1));
  bus_->frames.push_back(frameWith(*mapping_.steeringDeg, -12.5));
  bus_->frames.push_back(frameWith(*mapping_.speedKmh, 3.5, frameWith(*mapping_.indicator, 1)));
  can->poll(signals_, t0_);
  const VehicleSignals now = signals_.at(t0_);
  EXPECT_EQ(now.gear, Gear::kReverse);
  EXPECT_DOUBLE_EQ(now.steeringDeg, -12.5);
  EXPECT_DOUBLE_EQ(now.speedKmh.value_or(-1), 3.5);
  EXPECT_EQ(now.indicator, Indicator::kLeft);
  EXPECT_EQ(can->frames(), 3u);
  EXPECT_EQ(can->describe(t0_), "CAN can0: open, 3 frames");
  EXPECT_TRUE(bus_->frames.empty());

  // The newest frame wins; a gear number the mapping does not name reads as an unknown gear.
  bus_->frames.push_back(frameWith(*mapping_.gear, 3));
  bus_->frames.push_back(frameWith(*mapping_.gear, 15));
  can->poll(signals_, t0_ + 100ms);
  EXPECT_EQ(signals_.at(t0_ + 100ms).gear, Gear::kUnknown);
  bus_->frames.push_back(frameWith(*mapping_.gear, 3));
  can->poll(signals_, t0_ + 200ms);
  EXPECT_EQ(signals_.at(t0_ + 200ms).gear, Gear::kDrive);

  // A bus that goes quiet: each signal falls back to its default once stale.
  can->poll(signals_, t0_ + 1500ms);
  EXPECT_EQ(signals_.at(t0_ + 1500ms), VehicleSignals{});
}

TEST_F(CanSignalReaderTest, AFrameTooShortOrAnImplausibleNumberIsCountedAndTheRestTaken) {
  testing::LogCapture log;
  auto can = reader();
  // One byte: the indicator (bits 0-1) is there, the speed (bits 8-23) is not.
  CanFrame shortFrame = frameWith(*mapping_.indicator, 2);
  shortFrame.length = 1;
  bus_->frames.push_back(shortFrame);
  bus_->frames.push_back(frameWith(*mapping_.steeringDeg, 2000));  // past ±1080°
  can->poll(signals_, t0_);
  EXPECT_EQ(signals_.at(t0_).indicator, Indicator::kRight);
  EXPECT_EQ(signals_.at(t0_).speedKmh, std::nullopt);
  EXPECT_EQ(signals_.describe(t0_).find("steering 2000"), std::string::npos);
  EXPECT_EQ(can->unreadable(), 2u);
  EXPECT_EQ(can->describe(t0_),
            "CAN can0: open, 2 frames, 2 unreadable (last: frame 0x25: steering_deg: expected "
            "degrees in -1080..1080, got 2000)");
  // The first is logged, the rest counted in the status.
  EXPECT_THAT(log.lines(), ::testing::ElementsAre(HasSubstr(
                               "[warning] vehicle signals: CAN can0: frame 0x18FEF115 of 1 bytes "
                               "is too short for 'VehicleSpeed' (counted in the status")));
}

TEST_F(CanSignalReaderTest, ABusThatFailsIsOpenedAgainLessAndLessOftenAndSaidOnce) {
  testing::LogCapture log;
  bus_->openError = ENODEV;
  auto can = reader("can9");
  EXPECT_EQ(bus_->opens, 1);
  EXPECT_EQ(can->describe(t0_), "CAN can9: down (cannot open it: No such device), next try in 1 s");
  can->poll(signals_, t0_ + 900ms);
  EXPECT_EQ(bus_->opens, 1);
  can->poll(signals_, t0_ + 1s);  // fails again: 2 s to the next try
  EXPECT_EQ(bus_->opens, 2);
  can->poll(signals_, t0_ + 2900ms);
  EXPECT_EQ(bus_->opens, 2);
  can->poll(signals_, t0_ + 3s);  // and again: 4 s
  EXPECT_EQ(bus_->opens, 3);
  EXPECT_EQ(can->describe(t0_ + 3s),
            "CAN can9: down (cannot open it: No such device), next try in 4 s");

  bus_->openError = 0;
  bus_->frames.push_back(frameWith(*mapping_.gear, 1));
  can->poll(signals_, t0_ + 7s);
  EXPECT_EQ(bus_->opens, 4);
  EXPECT_EQ(signals_.at(t0_ + 7s).gear, Gear::kReverse);

  // The interface goes down while open: closed, and tried again a second later.
  bus_->receiveError = ENETDOWN;
  can->poll(signals_, t0_ + 8s);
  EXPECT_FALSE(bus_->open);
  EXPECT_THAT(can->describe(t0_ + 8s),
              HasSubstr("down (receiving: Network is down), next try in 1 s"));
  can->poll(signals_, t0_ + 9s);
  EXPECT_TRUE(bus_->open);

  const auto lines = log.lines();
  ASSERT_EQ(lines.size(), 4u) << ::testing::PrintToString(lines);
  EXPECT_THAT(lines[0], HasSubstr("[warning] vehicle signals: CAN can9: cannot open it: No such "
                                  "device; the signals it carries go stale, trying again in 1 s"));
  EXPECT_THAT(lines[1], HasSubstr("[info] vehicle signals: CAN can9 is open again"));
  EXPECT_THAT(lines[2],
              HasSubstr("[warning] vehicle signals: CAN can9: receiving: Network is down"));
  EXPECT_THAT(lines[3], HasSubstr("[info] vehicle signals: CAN can9 is open again"));
}

TEST(SocketCanBus, AnInterfaceThatIsNotThereIsNoSuchDevice) {
  const std::array<CanId, 1> ids{CanId{0x25, false}};
  EXPECT_EQ(makeSocketCanBus()->open("nosuchcan7", ids), ENODEV);
}

// Through the kernel: needs a vcan interface (root: `ip link add dev vcan0 type vcan; ip link set
// up vcan0`), which ctest's SocketCanBus.OnAVcanBus gives it on a virtual machine
// (scripts/device-vm.sh).
TEST(SocketCanBus, FramesGoThroughAVcanInterfaceFilteredByTheirIds) {
  if (::if_nametoindex("vcan0") == 0) {
    GTEST_SKIP() << "no vcan0 interface here (ctest runs this on a virtual machine's: "
                    "SocketCanBus.OnAVcanBus)";
  }
  const CanSignalMapping mapping = testMapping("vcan0");
  auto sender = makeSocketCanBus();
  ASSERT_EQ(sender->open("vcan0", {}), 0);
  CanSignalReader reader(mapping, makeSocketCanBus(), Clock::now());
  CanFrame other = frameWith(*mapping.gear, 3);
  other.id = 1161;  // not a mapped message: the kernel's filter drops it
  ASSERT_EQ(sender->send(other), 0);
  ASSERT_EQ(sender->send(frameWith(*mapping.gear, 1)), 0);
  ASSERT_EQ(sender->send(frameWith(*mapping.speedKmh, 12.34)), 0);
  VehicleSignalState signals(1s);
  const auto deadline = Clock::now() + 2s;
  while (reader.frames() < 2 && Clock::now() < deadline) {
    reader.poll(signals, Clock::now());
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_EQ(reader.frames(), 2u);
  EXPECT_EQ(signals.at(Clock::now()).gear, Gear::kReverse);
  EXPECT_NEAR(signals.at(Clock::now()).speedKmh.value_or(-1), 12.34, 0.005);
}

}  // namespace
}  // namespace surroundd::vehicle
