#include "vehicle/can_database.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

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

double number(std::string_view text, std::string_view origin, int line, const char* what) {
  // from_chars reads no sign '+', which DBC writers put before factors and offsets.
  const std::string_view written = text.starts_with('+') ? text.substr(1) : text;
  double value = 0;
  const auto [end, error] = std::from_chars(written.data(), written.data() + written.size(), value);
  if (error != std::errc{} || end != written.data() + written.size() || !std::isfinite(value)) {
    throw CanDatabaseError(
        fmt::format("{}:{}: {}: expected a number, got '{}'", origin, line, what, text));
  }
  return value;
}

// A whole number of at most `highest` (digits only, as DBC writes ids, lengths and bits).
std::uint32_t wholeNumber(std::string_view digits, std::uint32_t highest, std::string_view origin,
                          int line, const char* what) {
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (error != std::errc{} || end != digits.data() + digits.size() || value > highest) {
    throw CanDatabaseError(fmt::format("{}:{}: {}: expected a whole number of at most {}, got '{}'",
                                       origin, line, what, highest, digits));
  }
  return static_cast<std::uint32_t>(value);
}

// One DBC line, read left to right in a single pass. std::regex read these lines before: its
// matcher recurses once per character, and a line of ~40 KB overflowed the stack.
class LineScanner {
 public:
  explicit LineScanner(std::string_view line) : rest_(line) {}

  void skipSpace() {
    while (!rest_.empty() && isSpace(rest_.front())) rest_.remove_prefix(1);
  }
  // `word` at the start of the line (after blanks) and at least one blank after it.
  bool keyword(std::string_view word) {
    skipSpace();
    if (!rest_.starts_with(word) || rest_.size() == word.size() || !isSpace(rest_[word.size()])) {
      return false;
    }
    rest_.remove_prefix(word.size());
    skipSpace();
    return true;
  }
  // The character `c` next, with no blanks before it unless `blanksBefore`.
  bool literal(char c, bool blanksBefore = true) {
    if (blanksBefore) skipSpace();
    if (rest_.empty() || rest_.front() != c) return false;
    rest_.remove_prefix(1);
    return true;
  }
  // The longest run (at least one character) of characters that `accepts`; empty when none.
  template <class Accepts>
  std::string_view run(Accepts&& accepts) {
    std::size_t length = 0;
    while (length < rest_.size() && accepts(rest_[length])) ++length;
    const std::string_view taken = rest_.substr(0, length);
    rest_.remove_prefix(length);
    return taken;
  }
  std::string_view digits() {
    return run([](char c) { return c >= '0' && c <= '9'; });
  }
  std::string_view identifier() {
    return run([](char c) {
      return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
    });
  }
  // Characters up to a blank or `stop`.
  std::string_view until(char stop) {
    return run([stop](char c) { return c != stop && !isSpace(c); });
  }
  char peek() const { return rest_.empty() ? '\0' : rest_.front(); }

 private:
  static bool isSpace(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
  }

  std::string_view rest_;
};

// BO_ <id> <name>: <length> <sender>
struct MessageLine {
  std::string_view id, name, length;
};
std::optional<MessageLine> readMessageLine(std::string_view line) {
  LineScanner scan(line);
  MessageLine read;
  if (!scan.keyword("BO_") || (read.id = scan.digits()).empty()) return std::nullopt;
  scan.skipSpace();
  if ((read.name = scan.identifier()).empty() || !scan.literal(':')) return std::nullopt;
  scan.skipSpace();
  if ((read.length = scan.digits()).empty()) return std::nullopt;
  return read;
}

// "M" (the multiplexor) or "m<n>" / "m<n>M" (multiplexed by the multiplexor's value n).
bool isMultiplexIndicator(std::string_view word) {
  if (word == "M") return true;
  if (!word.starts_with('m')) return false;
  word.remove_prefix(1);
  if (word.ends_with('M')) word.remove_suffix(1);
  return !word.empty() && word.find_first_not_of("0123456789") == std::string_view::npos;
}

// SG_ <name> [M|m<n>[M]] : <start>|<length>@<order><sign> (<factor>,<offset>) ...
struct SignalLine {
  std::string_view name, multiplex, start, length, factor, offset;
  char order = 0, sign = 0;
};
std::optional<SignalLine> readSignalLine(std::string_view line) {
  LineScanner scan(line);
  SignalLine read;
  if (!scan.keyword("SG_") || (read.name = scan.identifier()).empty()) return std::nullopt;
  scan.skipSpace();
  if (scan.peek() != ':') {
    read.multiplex = scan.identifier();
    if (!isMultiplexIndicator(read.multiplex)) return std::nullopt;
  }
  if (!scan.literal(':')) return std::nullopt;
  scan.skipSpace();
  if ((read.start = scan.digits()).empty() || !scan.literal('|', false) ||
      (read.length = scan.digits()).empty() || !scan.literal('@', false)) {
    return std::nullopt;
  }
  read.order = scan.peek();
  if ((read.order != '0' && read.order != '1') || !scan.literal(read.order, false)) {
    return std::nullopt;
  }
  read.sign = scan.peek();
  if ((read.sign != '+' && read.sign != '-') || !scan.literal(read.sign, false)) {
    return std::nullopt;
  }
  if (!scan.literal('(')) return std::nullopt;
  scan.skipSpace();
  if ((read.factor = scan.until(',')).empty() || !scan.literal(',')) return std::nullopt;
  scan.skipSpace();
  if ((read.offset = scan.until(')')).empty() || !scan.literal(')')) return std::nullopt;
  return read;
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
    const std::string_view line = text.substr(at, end - at);
    at = end + 1;
    ++lineNumber;
    if (const auto read = readMessageLine(line)) {
      const std::uint32_t id = wholeNumber(read->id, 0xFFFFFFFFU, origin, lineNumber, "message id");
      message =
          Message{id & 0x1FFFFFFFU, (id & 0x80000000U) != 0,
                  static_cast<int>(wholeNumber(read->length, 0xFFFF, origin, lineNumber, "length")),
                  id == kIndependentSignals, std::string(read->name)};
      if (!message->independent && (message->bytes < 1 || message->bytes > 64)) {
        throw CanDatabaseError(fmt::format("{}:{}: message '{}' of {} bytes, expected 1..64",
                                           origin, lineNumber, message->name, message->bytes));
      }
      continue;
    }
    if (const auto read = readSignalLine(line)) {
      if (!message) {
        throw CanDatabaseError(fmt::format("{}:{}: signal '{}' before any message (BO_)", origin,
                                           lineNumber, read->name));
      }
      // A multiplexed signal means something only with its multiplexor's value: not read.
      if (message->independent || read->multiplex.starts_with('m')) continue;
      CanSignal signal;
      signal.name = std::string(read->name);
      signal.messageId = message->id;
      signal.extended = message->extended;
      // Past 64 bytes' bits a start or length is refused by problem() below.
      signal.startBit =
          static_cast<int>(wholeNumber(read->start, 0xFFFF, origin, lineNumber, "start bit"));
      signal.length =
          static_cast<int>(wholeNumber(read->length, 0xFFFF, origin, lineNumber, "length"));
      signal.order = read->order == '1' ? ByteOrder::kIntel : ByteOrder::kMotorola;
      signal.isSigned = read->sign == '-';
      signal.factor = number(read->factor, origin, lineNumber, "factor");
      signal.offset = number(read->offset, origin, lineNumber, "offset");
      if (const auto problem = signal.problem(message->bytes)) {
        throw CanDatabaseError(
            fmt::format("{}:{}: message '{}': {}", origin, lineNumber, message->name, *problem));
      }
      database.messageNames_.push_back(message->name);
      database.signals_.push_back(std::move(signal));
      continue;
    }
    LineScanner scan(line);
    if (scan.keyword("SG_")) {
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
