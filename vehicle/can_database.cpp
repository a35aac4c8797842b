#include "vehicle/can_database.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <regex>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace surroundd::vehicle {
namespace {

// Calls visit(position, weight) for each of the signal's bits, position in DBC numbering and
// weight its place in the raw value (0: least significant).
template <class Visit>
void forEachBit(const CanSignal& signal, Visit&& visit) {
  int position = signal.startBit;
  for (int i = 0; i < signal.length; ++i) {
    if (signal.order == ByteOrder::kIntel) {
      visit(signal.startBit + i, i);
    } else {
      visit(position, signal.length - 1 - i);
      // Down through the byte, then on to the next byte's most significant bit.
      position = position % 8 == 0 ? position + 15 : position - 1;
    }
  }
}

// How many bytes a frame needs to hold the signal.
int bytesNeeded(const CanSignal& signal) {
  int last = 0;
  forEachBit(signal, [&](int position, int) { last = std::max(last, position); });
  return last / 8 + 1;
}

std::uint64_t rawMask(int length) {
  return length >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << length) - 1;
}

double number(const std::string& text, std::string_view origin, int line, const char* what) {
  std::size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !std::isfinite(value)) {
    throw CanDatabaseError(
        fmt::format("{}:{}: {}: expected a number, got '{}'", origin, line, what, text));
  }
  return value;
}

}  // namespace

std::optional<std::string> CanSignal::problem(int maxBytes) const {
  if (length < 1 || length > 64) {
    return fmt::format("signal '{}': length {} bits, expected 1..64", name, length);
  }
  if (startBit < 0 || startBit >= maxBytes * 8) {
    return fmt::format("signal '{}': start bit {}, expected 0..{}", name, startBit,
                       maxBytes * 8 - 1);
  }
  if (bytesNeeded(*this) > maxBytes) {
    return fmt::format("signal '{}': {} bits from bit {} ({}) run past a {}-byte frame", name,
                       length, startBit, order == ByteOrder::kIntel ? "Intel" : "Motorola",
                       maxBytes);
  }
  if (factor == 0 || !std::isfinite(factor) || !std::isfinite(offset)) {
    return fmt::format("signal '{}': factor {} and offset {}, expected a non-zero factor", name,
                       factor, offset);
  }
  return std::nullopt;
}

std::optional<double> CanSignal::decode(std::span<const std::uint8_t> data) const {
  if (static_cast<int>(data.size()) < bytesNeeded(*this)) return std::nullopt;
  std::uint64_t raw = 0;
  forEachBit(*this, [&](int position, int weight) {
    const auto byte = data[static_cast<std::size_t>(position / 8)];
    if (((byte >> (position % 8)) & 1U) != 0) raw |= std::uint64_t{1} << weight;
  });
  double value = static_cast<double>(raw);
  if (isSigned && length < 64 && (raw >> (length - 1)) != 0) {
    value -= std::ldexp(1.0, length);  // two's complement
  } else if (isSigned && length == 64) {
    value = static_cast<double>(static_cast<std::int64_t>(raw));
  }
  return value * factor + offset;
}

void CanSignal::encode(double physical, std::span<std::uint8_t> data) const {
  const double lowest = isSigned ? -std::ldexp(1.0, length - 1) : 0.0;
  // One past the largest raw value, as a double (2^64 and 2^63 are exact; 2^64 - 1 is not).
  const double end = std::ldexp(1.0, isSigned ? length - 1 : length);
  const double highest = length >= 53 ? std::nextafter(end, 0.0) : end - 1;
  const double clamped = std::clamp(std::round((physical - offset) / factor), lowest, highest);
  const std::uint64_t raw =
      (isSigned ? static_cast<std::uint64_t>(static_cast<std::int64_t>(clamped))
                : static_cast<std::uint64_t>(clamped)) &
      rawMask(length);
  forEachBit(*this, [&](int position, int weight) {
    auto& byte = data[static_cast<std::size_t>(position / 8)];
    const auto bit = static_cast<std::uint8_t>(1U << (position % 8));
    byte = ((raw >> weight) & 1U) != 0 ? static_cast<std::uint8_t>(byte | bit)
                                       : static_cast<std::uint8_t>(byte & ~bit);
  });
}

CanDatabase CanDatabase::fromDbc(std::string_view text, std::string_view origin) {
  // BO_ <id> <name>: <length> <sender>
  static const std::regex kMessage(R"(^\s*BO_\s+(\d+)\s+(\w+)\s*:\s*(\d+))");
  // SG_ <name> [M|m<n>] : <start>|<length>@<order><sign> (<factor>,<offset>) ...
  static const std::regex kSignal(
      R"(^\s*SG_\s+(\w+)\s*(M|m\d+M?)?\s*:\s*(\d+)\|(\d+)@([01])([+-])\s*\(\s*([^,\s]+)\s*,\s*([^)\s]+)\s*\))");
  // The pseudo-message DBC editors keep signals that belong to no message in.
  constexpr std::uint32_t kIndependentSignals = 0xC0000000U;

  CanDatabase database;
  struct Message {
    std::uint32_t id = 0;
    bool extended = false;
    int bytes = 0;
    bool independent = false;
    std::string name;
  };
  std::optional<Message> message;
  int lineNumber = 0;
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::string line(text.substr(at, end - at));
    at = end + 1;
    ++lineNumber;
    std::smatch match;
    if (std::regex_search(line, match, kMessage)) {
      const auto id =
          static_cast<std::uint32_t>(number(match[1].str(), origin, lineNumber, "message id"));
      message = Message{id & 0x1FFFFFFFU, (id & 0x80000000U) != 0,
                        static_cast<int>(number(match[3].str(), origin, lineNumber, "length")),
                        id == kIndependentSignals, match[2].str()};
      if (!message->independent && (message->bytes < 1 || message->bytes > 64)) {
        throw CanDatabaseError(fmt::format("{}:{}: message '{}' of {} bytes, expected 1..64",
                                           origin, lineNumber, message->name, message->bytes));
      }
      continue;
    }
    if (std::regex_search(line, match, kSignal)) {
      if (!message) {
        throw CanDatabaseError(fmt::format("{}:{}: signal '{}' before any message (BO_)", origin,
                                           lineNumber, match[1].str()));
      }
      // A multiplexed signal means something only with its multiplexor's value: not read.
      if (message->independent || (match[2].matched && match[2].str()[0] == 'm')) continue;
      CanSignal signal;
      signal.name = match[1].str();
      signal.messageId = message->id;
      signal.extended = message->extended;
      signal.startBit = static_cast<int>(number(match[3].str(), origin, lineNumber, "start bit"));
      signal.length = static_cast<int>(number(match[4].str(), origin, lineNumber, "length"));
      signal.order = match[5].str() == "1" ? ByteOrder::kIntel : ByteOrder::kMotorola;
      signal.isSigned = match[6].str() == "-";
      signal.factor = number(match[7].str(), origin, lineNumber, "factor");
      signal.offset = number(match[8].str(), origin, lineNumber, "offset");
      if (const auto problem = signal.problem(message->bytes)) {
        throw CanDatabaseError(
            fmt::format("{}:{}: message '{}': {}", origin, lineNumber, message->name, *problem));
      }
      database.messageNames_.push_back(message->name);
      database.signals_.push_back(std::move(signal));
      continue;
    }
    const std::size_t first = line.find_first_not_of(" \t");
    if (first != std::string::npos && line.compare(first, 3, "SG_") == 0 &&
        first + 3 < line.size() && (line[first + 3] == ' ' || line[first + 3] == '\t')) {
      throw CanDatabaseError(
          fmt::format("{}:{}: a signal line (SG_) that does not read as "
                      "'SG_ NAME : START|LENGTH@ORDER SIGN (FACTOR,OFFSET)'",
                      origin, lineNumber));
    }
  }
  if (database.signals_.empty()) {
    throw CanDatabaseError(fmt::format("{}: no signals (no BO_ message with SG_ lines)", origin));
  }
  return database;
}

const CanSignal* CanDatabase::find(std::string_view name) const {
  // MESSAGE.SIGNAL, or SIGNAL alone when only one message has it.
  const std::size_t dot = name.find('.');
  const std::string_view messageName = dot == std::string_view::npos ? "" : name.substr(0, dot);
  const std::string_view signalName = dot == std::string_view::npos ? name : name.substr(dot + 1);
  const CanSignal* found = nullptr;
  std::vector<std::string> messages;
  for (std::size_t s = 0; s < signals_.size(); ++s) {
    if (signals_[s].name != signalName) continue;
    if (!messageName.empty() && messageNames_[s] != messageName) continue;
    found = &signals_[s];
    messages.push_back(messageNames_[s]);
  }
  if (messages.size() > 1) {
    throw CanDatabaseError(
        fmt::format("signal '{}' is in several messages ({}): name it as "
                    "MESSAGE.SIGNAL",
                    name, fmt::join(messages, ", ")));
  }
  return found;
}

}  // namespace surroundd::vehicle
