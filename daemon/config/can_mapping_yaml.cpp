#include "daemon/config/can_mapping_yaml.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "common/regular_file.hpp"
#include "vehicle/can_database.hpp"

namespace surroundd::daemon {
namespace {

// DBC files of whole vehicles run to a few MB.
constexpr std::size_t kMaxDatabaseBytes = std::size_t{64} << 20;
constexpr std::size_t kMaxInterfaceName = 15;  // IFNAMSIZ less its terminator

struct Database {
  vehicle::CanDatabase signals;
  std::string path;
};

// An id as CAN tools write it: 0x1F0 or 496.
std::optional<std::uint32_t> canId(std::string_view text) {
  int base = 10;
  if (text.starts_with("0x") || text.starts_with("0X")) {
    text.remove_prefix(2);
    base = 16;
  }
  std::uint32_t id = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), id, base);
  if (text.empty() || error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return id;
}

// A signal written out in the config, as a DBC's SG_ line would give it.
std::optional<vehicle::CanSignal> writtenOut(YamlObject& s, std::string_view key) {
  vehicle::CanSignal signal;
  signal.name = std::string(key);
  const std::string idText = s.requiredString("id").value_or("");
  signal.extended = s.boolean("extended", false);
  const auto id = canId(idText);
  const std::uint32_t maxId = signal.extended ? 0x1FFFFFFFU : 0x7FFU;
  if (!idText.empty() && (!id || *id > maxId)) {
    s.error("id", fmt::format("expected a {} CAN id, 0..0x{:X} (0x prefix for hexadecimal), got "
                              "'{}'{}",
                              signal.extended ? "29-bit" : "11-bit", maxId, idText,
                              signal.extended ? "" : "; extended: true for 29-bit ids"));
  }
  signal.messageId = id.value_or(0);
  signal.startBit = s.requiredInteger("start_bit", 0, 511).value_or(0);
  signal.length = s.requiredInteger("length", 1, 64).value_or(1);
  signal.order = s.choice(
      "byte_order", vehicle::ByteOrder::kIntel,
      {{"intel", vehicle::ByteOrder::kIntel}, {"motorola", vehicle::ByteOrder::kMotorola}});
  signal.isSigned = s.boolean("signed", false);
  signal.factor = s.number("factor", 1.0);
  signal.offset = s.number("offset", 0.0);
  if (const auto problem = signal.problem()) {
    s.errorHere(*problem);
    return std::nullopt;
  }
  return signal;
}

// The CAN signal of `s`: {signal: NAME} from the database, or written out; none when wrong
// (then said).
std::optional<vehicle::CanSignal> signalOf(YamlObject& s, std::string_view key,
                                           const std::optional<Database>& database) {
  if (!s.has("signal")) return writtenOut(s, key);
  const std::string name = s.string("signal", "");
  // Each asked, so that the one message says it all (has() marks a key as known).
  const bool writtenToo =
      std::ranges::count_if(std::array{"id", "extended", "start_bit", "length", "byte_order",
                                       "signed", "factor", "offset"},
                            [&](const char* written) { return s.has(written); }) > 0;
  if (writtenToo) {
    s.errorHere(
        "either 'signal' (a name in the database) or the signal written out (id, "
        "start_bit, length, ...), not both");
    return std::nullopt;
  }
  if (!database) {
    s.error("signal",
            fmt::format("'{}' names a signal of a DBC file, but 'database' is not set", name));
    return std::nullopt;
  }
  try {
    if (const auto* found = database->signals.find(name)) return *found;
    s.error("signal", fmt::format("no signal '{}' in {}", name, database->path));
  } catch (const vehicle::CanDatabaseError& e) {
    s.error("signal", fmt::format("{} ({})", e.what(), database->path));
  }
  return std::nullopt;
}

// `values: {NAME: NUMBER, ...}` of `s` for the names of `meanings`, at least one of them.
template <class T, std::size_t N>
std::vector<std::pair<double, T>> readValues(
    YamlObject& s, const std::array<std::pair<const char*, T>, N>& meanings) {
  std::vector<std::pair<double, T>> values;
  std::string names;
  for (const auto& [name, meaning] : meanings) {
    names += fmt::format("{}{}", names.empty() ? "" : ", ", name);
  }
  auto object = s.object("values");
  if (!object) {
    s.errorHere(fmt::format("missing key 'values': which of the signal's numbers mean {}", names));
    return values;
  }
  for (const auto& [name, meaning] : meanings) {
    if (object->has(name)) values.emplace_back(object->number(name, 0.0), meaning);
  }
  if (values.empty()) object->errorHere(fmt::format("expected the numbers of {}", names));
  object->finish();
  return values;
}

// The CAN signal under `key` of `can`, if there; `values` reads a gear's or an indicator's.
template <class T = int, std::size_t N = 0>
std::optional<vehicle::CanSignal> readSignal(
    YamlObject& can, std::string_view key, const std::optional<Database>& database,
    const std::array<std::pair<const char*, T>, N>* meanings = nullptr,
    std::vector<std::pair<double, T>>* values = nullptr) {
  auto s = can.object(key);
  if (!s) return std::nullopt;
  auto signal = signalOf(*s, key, database);
  if (meanings != nullptr) *values = readValues(*s, *meanings);
  s->finish();
  return signal;
}

constexpr std::array<std::pair<const char*, vehicle::Gear>, 4> kGearNames{
    {{"P", vehicle::Gear::kPark},
     {"R", vehicle::Gear::kReverse},
     {"N", vehicle::Gear::kNeutral},
     {"D", vehicle::Gear::kDrive}}};
constexpr std::array<std::pair<const char*, vehicle::Indicator>, 4> kIndicatorNames{
    {{"off", vehicle::Indicator::kOff},
     {"left", vehicle::Indicator::kLeft},
     {"right", vehicle::Indicator::kRight},
     {"hazard", vehicle::Indicator::kHazard}}};

}  // namespace

void readCanMapping(YamlObject& section, VehicleSignalsConfig& c) {
  auto can = section.object("can");
  if (!can) return;
  vehicle::CanSignalMapping mapping;
  mapping.interface = can->requiredString("interface").value_or("");
  if (can->has("interface") &&
      (mapping.interface.empty() || mapping.interface.size() > kMaxInterfaceName ||
       mapping.interface.find_first_of("/ \t") != std::string::npos)) {
    can->error("interface", fmt::format("expected a network interface name of 1 to {} characters "
                                        "(can0, vcan0), got '{}'",
                                        kMaxInterfaceName, mapping.interface));
  }
  std::optional<Database> database;
  if (can->has("database")) {
    if (const auto path = can->existingFile("database")) {
      try {
        database = Database{vehicle::CanDatabase::fromDbc(readRegularFile(*path, kMaxDatabaseBytes),
                                                          path->string()),
                            path->string()};
      } catch (const std::exception& e) {  // FileReadError, CanDatabaseError
        can->error("database", e.what());
      }
    }
  }
  mapping.gear = readSignal(*can, "gear", database, &kGearNames, &mapping.gearValues);
  mapping.indicator =
      readSignal(*can, "indicator", database, &kIndicatorNames, &mapping.indicatorValues);
  mapping.steeringDeg = readSignal(*can, "steering_deg", database);
  mapping.speedKmh = readSignal(*can, "speed_kmh", database);
  if (!can->has("gear") && !can->has("indicator") && !can->has("steering_deg") &&
      !can->has("speed_kmh")) {
    can->errorHere(
        "expected the signals it carries: gear, steering_deg, speed_kmh and/or "
        "indicator");
  }
  can->finish();
  c.can = std::move(mapping);
}

}  // namespace surroundd::daemon
