#pragma once
// Where a vehicle's signals sit in its CAN frames: CanSignal (message id, start bit, length, byte
// order, sign, factor and offset, as a CAN database defines them) and CanDatabase, the signals of
// a DBC file — the subset of it that places signals: `BO_` (messages) and `SG_` (their signals)
// lines; everything else in the file (nodes, comments, attributes, value tables) is skipped.
//
// Bits are numbered as DBC files number them: bit b is bit b % 8 of byte b / 8. An Intel
// (little-endian, `@1`) signal starts at its least significant bit and runs up; a Motorola
// (big-endian, `@0`) one starts at its most significant bit and runs down through each byte, then
// on to the next byte's bit 7.
//
// Errors: parsing throws CanDatabaseError naming the file and line (start-up, config load);
// decoding returns nothing for a frame too short to hold the signal.

#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace surroundd::vehicle {

class CanDatabaseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class ByteOrder { kIntel, kMotorola };

struct CanSignal {
  std::string name;
  std::uint32_t messageId = 0;  // 11 bits, or 29 with `extended`
  bool extended = false;
  int startBit = 0;  // DBC numbering (above)
  int length = 1;    // 1..64 bits
  ByteOrder order = ByteOrder::kIntel;
  bool isSigned = false;  // two's complement
  double factor = 1;      // physical = raw * factor + offset
  double offset = 0;

  bool operator==(const CanSignal&) const = default;

  // Why the signal cannot be read from frames of `maxBytes` (a length out of 1..64, a bit past
  // the frame's end, a factor of 0); none when it can.
  std::optional<std::string> problem(int maxBytes = 64) const;
  // The physical value in `data` (one frame's payload); none when the frame is too short.
  std::optional<double> decode(std::span<const std::uint8_t> data) const;
  // Writes `physical` (rounded to the nearest raw value, clamped to the raw range) into `data`,
  // leaving its other bits as they are: the inverse of decode(), for what plays a vehicle's part
  // on a bus (a bench, a simulator, the tests).
  void encode(double physical, std::span<std::uint8_t> data) const;
};

class CanDatabase {
 public:
  // `origin` names the text in errors (the file's path).
  static CanDatabase fromDbc(std::string_view text, std::string_view origin);

  // The signal named `name` — SIGNAL, or MESSAGE.SIGNAL — case-sensitive as DBC names are; null
  // when there is none. Throws CanDatabaseError when several messages have a SIGNAL of the name.
  const CanSignal* find(std::string_view name) const;
  const std::vector<CanSignal>& signals() const { return signals_; }

 private:
  std::vector<CanSignal> signals_;
  std::vector<std::string> messageNames_;  // each signal's message
};

}  // namespace surroundd::vehicle
