// The DBC reader (CanDatabase::fromDbc) on any text: a database whose every signal can be read
// from a frame of its message (CanSignal::problem), or CanDatabaseError; anything else (a crash,
// a hang on a long line) is a finding.

#include <array>
#include <cstddef>
#include <cstdint>

#include "tests/fuzz/fuzz_support.hpp"
#include "vehicle/can_database.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto database =
        surroundd::vehicle::CanDatabase::fromDbc(surroundd::fuzz::asText(data, size), "car.dbc");
    FUZZ_CHECK(!database.signals().empty());
    std::array<std::uint8_t, 64> frame{};
    for (const auto& signal : database.signals()) {
      FUZZ_CHECK(!signal.problem());
      FUZZ_CHECK(signal.decode(frame).has_value());
      signal.encode(1.0, frame);  // within the frame: ASan would see a write past it
    }
  } catch (const surroundd::vehicle::CanDatabaseError&) {
    // the documented answer to a bad file
  }
  return 0;
}
