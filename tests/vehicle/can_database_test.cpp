// CAN signals placed in frames as DBC files place them, checked against frames laid out by hand
// (each byte worked out from the DBC bit numbering), and a DBC file read with the lines surroundd
// takes and those it skips.

#include "vehicle/can_database.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace surroundd::vehicle {
namespace {

using ::testing::HasSubstr;

CanSignal signal(int start, int length, ByteOrder order, bool isSigned = false, double factor = 1,
                 double offset = 0) {
  CanSignal s;
  s.name = "s";
  s.startBit = start;
  s.length = length;
  s.order = order;
  s.isSigned = isSigned;
  s.factor = factor;
  s.offset = offset;
  return s;
}

std::string testDbc() {
  std::ifstream file(std::filesystem::path(SURROUNDD_SOURCE_DIR) /
                     "tests/vehicle/test_vehicle.dbc");
  return {std::istreambuf_iterator<char>(file), {}};
}

// 0xABC in 12 bits across two bytes: Intel from bit 4 up (its low nibble in byte 0's high one),
// Motorola from bit 3 down (its high nibble in byte 0's low one, then all of byte 1).
TEST(CanSignal, IntelAndMotorolaBitsAreWhereTheDbcNumberingPutsThem) {
  const std::array<std::uint8_t, 8> intel{0xC0, 0xAB};
  EXPECT_EQ(signal(4, 12, ByteOrder::kIntel).decode(intel), 0xABC);
  const std::array<std::uint8_t, 8> motorola{0x0A, 0xBC};
  EXPECT_EQ(signal(3, 12, ByteOrder::kMotorola).decode(motorola), 0xABC);
  // A whole big-endian word from byte 0's bit 7; the same bytes read little-endian.
  const std::array<std::uint8_t, 2> word{0x12, 0x34};
  EXPECT_EQ(signal(7, 16, ByteOrder::kMotorola).decode(word), 0x1234);
  EXPECT_EQ(signal(0, 16, ByteOrder::kIntel).decode(word), 0x3412);
  // 64 bits: every bit of the frame (2^63 + 1, the nearest double 2^63).
  const std::array<std::uint8_t, 8> all{1, 0, 0, 0, 0, 0, 0, 0x80};
  EXPECT_EQ(signal(0, 64, ByteOrder::kIntel).decode(all), std::ldexp(1.0, 63));
}

TEST(CanSignal, SignedValuesAreTwosComplementThenScaledAndOffset) {
  const std::array<std::uint8_t, 2> minusOne{0xF0, 0xFF};
  EXPECT_EQ(signal(4, 12, ByteOrder::kIntel, true).decode(minusOne), -1);
  EXPECT_EQ(signal(4, 12, ByteOrder::kIntel, false).decode(minusOne), 4095);
  // -12.5 degrees at 0.1 a step: raw -125, 0xFF83 big-endian.
  const std::array<std::uint8_t, 2> steering{0xFF, 0x83};
  EXPECT_DOUBLE_EQ(*signal(7, 16, ByteOrder::kMotorola, true, 0.1).decode(steering), -12.5);
  const std::array<std::uint8_t, 1> offset{200};
  EXPECT_DOUBLE_EQ(*signal(0, 8, ByteOrder::kIntel, false, 0.5, -40).decode(offset), 60);
  // The most negative 64-bit value.
  const std::array<std::uint8_t, 8> lowest{0, 0, 0, 0, 0, 0, 0, 0x80};
  EXPECT_DOUBLE_EQ(*signal(0, 64, ByteOrder::kIntel, true).decode(lowest), -9223372036854775808.0);
}

TEST(CanSignal, AFrameTooShortForTheSignalReadsAsNothing) {
  const std::array<std::uint8_t, 1> one{0xFF};
  EXPECT_EQ(signal(4, 12, ByteOrder::kIntel).decode(one), std::nullopt);
  EXPECT_EQ(signal(3, 12, ByteOrder::kMotorola).decode(one), std::nullopt);
  EXPECT_EQ(signal(0, 8, ByteOrder::kIntel).decode(one), 255);
}

// Encoding is decoding's inverse for every layout and value, and leaves the frame's other bits.
TEST(CanSignal, EncodingWritesOnlyTheSignalsBitsAndDecodesBack) {
  std::mt19937 random(21);
  for (int trial = 0; trial < 2000; ++trial) {
    const int length = std::uniform_int_distribution(1, 32)(random);
    const auto order = trial % 2 == 0 ? ByteOrder::kIntel : ByteOrder::kMotorola;
    const int start = std::uniform_int_distribution(0, 63)(random);
    const CanSignal s = signal(start, length, order, trial % 3 == 0, 0.25, -10);
    if (s.problem(8)) continue;
    const double lowest = s.isSigned ? -std::ldexp(1.0, length - 1) : 0;
    const auto raw = static_cast<double>(std::uniform_int_distribution<long long>(
        static_cast<long long>(lowest),
        static_cast<long long>(lowest + std::ldexp(1.0, length) - 1))(random));
    std::array<std::uint8_t, 8> frame{};
    for (auto& byte : frame) byte = static_cast<std::uint8_t>(random());
    const auto before = frame;
    s.encode(raw * 0.25 - 10, frame);
    ASSERT_EQ(s.decode(frame), raw * 0.25 - 10) << "start " << start << " length " << length;
    // Writing the value that was there before gives the frame as it was.
    s.encode(*s.decode(before), frame);
    ASSERT_EQ(frame, before) << "start " << start << " length " << length;
  }
}

// Past the raw range: the nearest end, also for 64-bit signals (whose ends doubles cannot hold
// exactly).
TEST(CanSignal, EncodingClampsToTheRawRange) {
  std::array<std::uint8_t, 8> frame{};
  const CanSignal small = signal(0, 8, ByteOrder::kIntel, true);
  small.encode(1000, frame);
  EXPECT_EQ(small.decode(frame), 127);
  small.encode(-1000, frame);
  EXPECT_EQ(small.decode(frame), -128);
  const CanSignal wide = signal(0, 64, ByteOrder::kIntel);
  wide.encode(1e30, frame);
  EXPECT_EQ(frame, (std::array<std::uint8_t, 8>{0, 0xF8, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}));
  const CanSignal wideSigned = signal(0, 64, ByteOrder::kIntel, true);
  wideSigned.encode(-1e30, frame);
  EXPECT_EQ(wideSigned.decode(frame), -std::ldexp(1.0, 63));
}

TEST(CanSignal, ALayoutPastTheFrameIsNamed) {
  EXPECT_THAT(signal(60, 8, ByteOrder::kIntel).problem(8).value_or(""),
              HasSubstr("8 bits from bit 60 (Intel) run past a 8-byte frame"));
  // Motorola from bit 56 runs down into bytes after the 8th.
  EXPECT_THAT(signal(56, 8, ByteOrder::kMotorola).problem(8).value_or(""), HasSubstr("run past"));
  EXPECT_EQ(signal(63, 8, ByteOrder::kMotorola).problem(8), std::nullopt);
  EXPECT_THAT(signal(0, 65, ByteOrder::kIntel).problem().value_or(""), HasSubstr("length 65"));
  EXPECT_THAT(signal(0, 8, ByteOrder::kIntel, false, 0).problem().value_or(""),
              HasSubstr("non-zero factor"));
}

TEST(CanDatabase, ReadsTheMessagesAndSignalsOfADbcFile) {
  const CanDatabase database = CanDatabase::fromDbc(testDbc(), "test_vehicle.dbc");
  const CanSignal* gear = database.find("GearLever");
  ASSERT_NE(gear, nullptr);
  EXPECT_EQ(gear->messageId, 1160u);
  EXPECT_FALSE(gear->extended);
  EXPECT_EQ(gear->startBit, 3);
  EXPECT_EQ(gear->length, 4);
  EXPECT_EQ(gear->order, ByteOrder::kIntel);

  const CanSignal* steering = database.find("SteeringWheelAngle");
  ASSERT_NE(steering, nullptr);
  EXPECT_EQ(steering->order, ByteOrder::kMotorola);
  EXPECT_TRUE(steering->isSigned);
  EXPECT_DOUBLE_EQ(steering->factor, 0.1);

  // A 29-bit id: bit 31 of the DBC's number marks it.
  const CanSignal* speed = database.find("BodyStatus.VehicleSpeed");
  ASSERT_NE(speed, nullptr);
  EXPECT_TRUE(speed->extended);
  EXPECT_EQ(speed->messageId, 0x18FEF115u);
  EXPECT_DOUBLE_EQ(speed->factor, 0.01);

  // The multiplexor is read, the signals it multiplexes and those of no message are not.
  EXPECT_NE(database.find("Selector"), nullptr);
  EXPECT_EQ(database.find("ValueA"), nullptr);
  EXPECT_EQ(database.find("Unplaced"), nullptr);
  EXPECT_EQ(database.find("NoSuchSignal"), nullptr);

  // A name two messages have is asked for with its message.
  EXPECT_THAT([&] { database.find("GearCounter"); },
              ::testing::ThrowsMessage<CanDatabaseError>(
                  HasSubstr("signal 'GearCounter' is in several messages (Gearbox, Trailer)")));
  ASSERT_NE(database.find("Trailer.GearCounter"), nullptr);
  EXPECT_EQ(database.find("Trailer.GearCounter")->messageId, 1025u);
}

TEST(CanDatabase, ABadLineIsNamedWithItsFileAndLine) {
  const auto refused = [](const std::string& text, const std::string& message) {
    EXPECT_THAT([&] { CanDatabase::fromDbc(text, "car.dbc"); },
                ::testing::ThrowsMessage<CanDatabaseError>(HasSubstr(message)))
        << text;
  };
  refused("BO_ 1 A: 8 X\n SG_ S : 0|8@1+ (1,0) [0|0] \"\" Y\n SG_ T : 0|8@2+ (1,0)\n",
          "car.dbc:3: a signal line (SG_) that does not read as");
  refused("\n SG_ S : 0|8@1+ (1,0) [0|0] \"\" Y\n", "car.dbc:2: signal 'S' before any message");
  refused("BO_ 1 A: 2 X\n SG_ S : 12|8@1+ (1,0) [0|0] \"\" Y\n",
          "car.dbc:2: message 'A': signal 'S': 8 bits from bit 12 (Intel) run past a 2-byte frame");
  refused("BO_ 1 A: 8 X\n SG_ S : 0|8@1+ (0,0) [0|0] \"\" Y\n", "non-zero factor");
  refused("BO_ 1 A: 8 X\n SG_ S : 0|8@1+ (x,0) [0|0] \"\" Y\n",
          "car.dbc:2: factor: expected a number, got 'x'");
  refused("BO_ 1 A: 99 X\n", "car.dbc:1: message 'A' of 99 bytes");
  refused("VERSION \"\"\n", "car.dbc: no signals");
}

// Issue 51: a line of ~40 KB overflowed the stack of the recursive std::regex that read lines, in
// --check-config and on a reload, which ended the daemon. Lines of a few megabytes of every shape
// the reader meets are now read, or refused naming the line.
TEST(CanDatabase, LinesOfMegabytesAreReadOrRefusedWithoutCrashing) {
  constexpr std::size_t kLong = 4 << 20;
  const std::string message = "BO_ 1 A: 8 X\n";
  const std::string signal = " SG_ S : 0|8@1+ (1,0) [0|0] \"\" Y\n";
  // A comment, blanks before a keyword, a signal's long name and long factor, a long id.
  const std::string comment = "CM_ \"" + std::string(kLong, 'c') + "\";\n";
  EXPECT_EQ(CanDatabase::fromDbc(comment + message + signal, "car.dbc").signals().size(), 1u);
  EXPECT_EQ(
      CanDatabase::fromDbc(message + std::string(kLong, ' ') + signal, "car.dbc").signals().size(),
      1u);
  const std::string name(kLong, 'N');
  const CanDatabase longName =
      CanDatabase::fromDbc(message + " SG_ " + name + " : 0|8@1+ (1,0)\n", "car.dbc");
  ASSERT_EQ(longName.signals().size(), 1u);
  EXPECT_EQ(longName.signals()[0].name, name);
  EXPECT_THAT(
      [&] {
        CanDatabase::fromDbc(message + " SG_ S : 0|8@1+ (" + std::string(kLong, '1') + ",0)\n",
                             "car.dbc");
      },
      ::testing::ThrowsMessage<CanDatabaseError>(
          HasSubstr("car.dbc:2: factor: expected a number")));
  EXPECT_THAT(
      [&] { CanDatabase::fromDbc("BO_ " + std::string(kLong, '9') + " A: 8 X\n", "car.dbc"); },
      ::testing::ThrowsMessage<CanDatabaseError>(
          HasSubstr("car.dbc:1: message id: expected a whole number of at most 4294967295")));
  EXPECT_THAT(
      [&] { CanDatabase::fromDbc(message + " SG_ " + std::string(kLong, '(') + "\n", "car.dbc"); },
      ::testing::ThrowsMessage<CanDatabaseError>(
          HasSubstr("car.dbc:2: a signal line (SG_) that does not read as")));
}

// What the regular expressions took, the line reader takes alike: blanks where DBC writers put
// them, multiplex indicators, a '+' before numbers, CRLF line ends; numbers past their field's
// range are refused rather than cast.
TEST(CanDatabase, ReadsTheLineShapesDbcWritersUse) {
  const CanDatabase database = CanDatabase::fromDbc(
      "BO_ 2147484672 Ext : 8 X\r\n"
      "\tSG_ Mux M : 0|4@1+ (1,0) [0|15] \"\" Y\r\n"
      " SG_ Muxed m3 : 8|8@1+ (1,0) [0|0] \"\" Y\r\n"
      " SG_ Both m1M : 16|8@1+ (1,0) [0|0] \"\" Y\r\n"
      " SG_ Plain:24|16@0-(+0.5 , -3e1) [0|0] \"\" Y\r\n",
      "car.dbc");
  ASSERT_EQ(database.signals().size(), 2u);
  EXPECT_EQ(database.signals()[0].name, "Mux");
  const CanSignal& plain = database.signals()[1];
  EXPECT_EQ(plain.name, "Plain");
  EXPECT_TRUE(plain.extended);
  EXPECT_EQ(plain.messageId, 1024u);
  EXPECT_EQ(plain.startBit, 24);
  EXPECT_EQ(plain.length, 16);
  EXPECT_EQ(plain.order, ByteOrder::kMotorola);
  EXPECT_TRUE(plain.isSigned);
  EXPECT_DOUBLE_EQ(plain.factor, 0.5);
  EXPECT_DOUBLE_EQ(plain.offset, -30);
  EXPECT_THAT([] { CanDatabase::fromDbc("BO_ 1 A: 8 X\n SG_ S x : 0|8@1+ (1,0)\n", "car.dbc"); },
              ::testing::ThrowsMessage<CanDatabaseError>(HasSubstr("car.dbc:2: a signal line")));
  EXPECT_THAT(
      [] { CanDatabase::fromDbc("BO_ 1 A: 8 X\n SG_ S : 99999999999|8@1+ (1,0)\n", "car.dbc"); },
      ::testing::ThrowsMessage<CanDatabaseError>(
          HasSubstr("car.dbc:2: start bit: expected a whole")));
  EXPECT_THAT([] { CanDatabase::fromDbc("BO_ 4294967296 A: 8 X\n", "car.dbc"); },
              ::testing::ThrowsMessage<CanDatabaseError>(HasSubstr("car.dbc:1: message id")));
}

}  // namespace
}  // namespace surroundd::vehicle
