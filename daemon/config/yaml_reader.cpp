#include "daemon/config/yaml_reader.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <fmt/format.h>

#include "common/regular_file.hpp"

namespace surroundd::daemon {
namespace {

// A config or rig file is a page of text; far more is no config of ours.
constexpr std::size_t kMaxYamlBytes = std::size_t{16} << 20;

std::string joinLines(const std::vector<std::string>& lines) {
  std::string all;
  for (const auto& line : lines) {
    if (!all.empty()) all += '\n';
    all += line;
  }
  return all;
}

// What the user wrote, for "got ..." in messages.
std::string describe(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Scalar: {
      std::string text = node.Scalar();
      if (text.size() > 40) text = text.substr(0, 37) + "...";
      return "'" + text + "'";
    }
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a map";
    case YAML::NodeType::Null:
      return "nothing";
    case YAML::NodeType::Undefined:
      break;
  }
  return "nothing";
}

std::string formatNumber(double value) { return fmt::format("{:g}", value); }

std::string describeRange(const NumberRange& range) {
  std::string text = "a number";
  const bool hasMin = range.min > -1e299;
  const bool hasMax = range.max < 1e299;
  if (hasMin && hasMax && !range.minExclusive) {
    text += fmt::format(" in [{}, {}]", formatNumber(range.min), formatNumber(range.max));
  } else {
    if (hasMin)
      text += fmt::format(" {} {}", range.minExclusive ? ">" : ">=", formatNumber(range.min));
    if (hasMax) text += fmt::format("{} <= {}", hasMin ? " and" : "", formatNumber(range.max));
  }
  if (!range.unit.empty()) text += fmt::format(" ({})", range.unit);
  return text;
}

bool inRange(double value, const NumberRange& range) {
  if (!std::isfinite(value)) return false;
  if (range.minExclusive ? value <= range.min : value < range.min) return false;
  return value <= range.max;
}

}  // namespace

ConfigError::ConfigError(std::vector<std::string> messages)
    : std::runtime_error(joinLines(messages)), messages_(std::move(messages)) {}

void Diagnostics::error(const std::filesystem::path& file, const YAML::Mark& mark,
                        std::string_view keyPath, std::string_view message) {
  // yaml-cpp marks are 0-based; editors count from 1. A null mark (pos -1) has no position.
  const std::string where =
      mark.is_null() ? file.string()
                     : fmt::format("{}:{}:{}", file.string(), mark.line + 1, mark.column + 1);
  messages_.push_back(keyPath.empty() ? fmt::format("{}: {}", where, message)
                                      : fmt::format("{}: {}: {}", where, keyPath, message));
}

void Diagnostics::throwIfAny() const {
  if (!messages_.empty()) throw ConfigError(messages_);
}

YAML::Node parseYamlFile(const std::filesystem::path& file) {
  std::string text;
  try {
    text = readRegularFile(file, kMaxYamlBytes);
  } catch (const FileReadError& e) {
    throw ConfigError({fmt::format("cannot open the file {}", e.what())});
  }
  return parseYamlText(text, file);
}

YAML::Node parseYamlText(const std::string& text, const std::filesystem::path& file) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    Diagnostics diag;
    diag.error(file, e.mark, "", fmt::format("not valid YAML: {}", e.msg));
    diag.throwIfAny();
  }
  return {};
}

YamlObject::YamlObject(const YAML::Node& node, std::string keyPath, std::filesystem::path file,
                       Diagnostics& diag)
    : node_(node),
      keyPath_(std::move(keyPath)),
      file_(std::move(file)),
      diag_(&diag),
      mark_(node_.Mark()) {
  if (!node_.IsMap() && !node_.IsNull()) {
    errorHere(fmt::format("expected a map of keys, got {}", describe(node_)));
    node_ = YAML::Node(YAML::NodeType::Map);
  }
}

std::string YamlObject::childPath(std::string_view key) const {
  return keyPath_.empty() ? std::string(key) : fmt::format("{}.{}", keyPath_, key);
}

YAML::Mark YamlObject::markOf(std::string_view key) const {
  if (node_.IsMap()) {
    for (const auto& entry : node_) {
      if (entry.first.Scalar() == key)
        return entry.second.Mark().is_null() ? entry.first.Mark() : entry.second.Mark();
    }
  }
  return mark_;
}

void YamlObject::error(std::string_view key, std::string_view message) {
  diag_->error(file_, markOf(key), childPath(key), message);
}

void YamlObject::errorHere(std::string_view message) {
  diag_->error(file_, mark_, keyPath_, message);
}

bool YamlObject::has(std::string_view key) {
  known_.emplace(key);
  return node_.IsMap() && at(key).IsDefined();
}

std::optional<YAML::Node> YamlObject::scalar(std::string_view key, std::string_view expected) {
  if (!has(key)) return std::nullopt;
  YAML::Node value = at(key);
  if (!value.IsScalar()) {
    error(key, fmt::format("expected {}, got {}", expected, describe(value)));
    return std::nullopt;
  }
  return value;
}

std::optional<double> YamlObject::requiredNumber(std::string_view key, const NumberRange& range) {
  const std::string expected = describeRange(range);
  if (!has(key)) {
    errorHere(fmt::format("missing key '{}' ({})", key, expected));
    return std::nullopt;
  }
  const auto value = scalar(key, expected);
  if (!value) return std::nullopt;
  double number = 0;
  if (!YAML::convert<double>::decode(*value, number) || !inRange(number, range)) {
    error(key, fmt::format("expected {}, got {}", expected, describe(*value)));
    return std::nullopt;
  }
  return number;
}

double YamlObject::number(std::string_view key, double fallback, const NumberRange& range) {
  if (!has(key)) return fallback;
  return requiredNumber(key, range).value_or(fallback);
}

std::optional<int> YamlObject::requiredInteger(std::string_view key, int min, int max) {
  const std::string expected = fmt::format("a whole number in [{}, {}]", min, max);
  if (!has(key)) {
    errorHere(fmt::format("missing key '{}' ({})", key, expected));
    return std::nullopt;
  }
  const auto value = scalar(key, expected);
  if (!value) return std::nullopt;
  long long number = 0;
  if (!YAML::convert<long long>::decode(*value, number) || number < min || number > max) {
    error(key, fmt::format("expected {}, got {}", expected, describe(*value)));
    return std::nullopt;
  }
  return static_cast<int>(number);
}

int YamlObject::integer(std::string_view key, int fallback, int min, int max) {
  if (!has(key)) return fallback;
  return requiredInteger(key, min, max).value_or(fallback);
}

bool YamlObject::boolean(std::string_view key, bool fallback) {
  const auto value = scalar(key, "true or false");
  if (!value) return fallback;
  bool result = fallback;
  if (!YAML::convert<bool>::decode(*value, result)) {
    error(key, fmt::format("expected true or false, got {}", describe(*value)));
    return fallback;
  }
  return result;
}

std::optional<std::string> YamlObject::requiredString(std::string_view key) {
  if (!has(key)) {
    errorHere(fmt::format("missing key '{}' (a string)", key));
    return std::nullopt;
  }
  const auto value = scalar(key, "a string");
  if (!value) return std::nullopt;
  if (value->Scalar().empty()) {
    error(key, "expected a non-empty string");
    return std::nullopt;
  }
  return value->Scalar();
}

std::string YamlObject::string(std::string_view key, std::string fallback) {
  if (!has(key)) return fallback;
  return requiredString(key).value_or(std::move(fallback));
}

std::optional<std::vector<double>> YamlObject::numbers(std::string_view key,
                                                       std::initializer_list<std::size_t> sizes) {
  std::string counts;
  for (const auto size : sizes) counts += (counts.empty() ? "" : " or ") + std::to_string(size);
  return numberList(key, fmt::format("a list of {} numbers", counts), [&](std::size_t size) {
    return std::find(sizes.begin(), sizes.end(), size) != sizes.end();
  });
}

std::optional<std::vector<double>> YamlObject::numbers(std::string_view key, std::size_t minSize,
                                                       std::size_t maxSize) {
  return numberList(key, fmt::format("a list of {} to {} numbers", minSize, maxSize),
                    [&](std::size_t size) { return size >= minSize && size <= maxSize; });
}

std::optional<std::vector<std::string>> YamlObject::strings(std::string_view key,
                                                            std::size_t minSize,
                                                            std::size_t maxSize) {
  if (!has(key)) return std::nullopt;
  const std::string expected = fmt::format("a list of {} to {} names", minSize, maxSize);
  YAML::Node list = at(key);
  if (!list.IsSequence() || list.size() < minSize || list.size() > maxSize) {
    error(key,
          fmt::format("expected {}, got {}", expected,
                      list.IsSequence() ? fmt::format("{} items", list.size()) : describe(list)));
    return std::nullopt;
  }
  std::vector<std::string> result;
  for (const auto& item : list) {
    if (!item.IsScalar() || item.Scalar().empty()) {
      diag_->error(file_, item.Mark(), childPath(key),
                   fmt::format("expected {}, got {}", expected, describe(item)));
      return std::nullopt;
    }
    result.push_back(item.Scalar());
  }
  return result;
}

std::optional<std::vector<double>> YamlObject::numberList(
    std::string_view key, const std::string& expected,
    const std::function<bool(std::size_t)>& sizeFits) {
  if (!has(key)) return std::nullopt;
  YAML::Node list = at(key);
  if (!list.IsSequence() || !sizeFits(list.size())) {
    error(key,
          fmt::format("expected {}, got {}", expected,
                      list.IsSequence() ? fmt::format("{} items", list.size()) : describe(list)));
    return std::nullopt;
  }
  std::vector<double> result;
  for (const auto& item : list) {
    double number = 0;
    if (!item.IsScalar() || !YAML::convert<double>::decode(item, number) ||
        !std::isfinite(number)) {
      diag_->error(file_, item.Mark(), childPath(key),
                   fmt::format("expected {}, got {}", expected, describe(item)));
      return std::nullopt;
    }
    result.push_back(number);
  }
  return result;
}

std::optional<std::vector<std::array<double, 2>>> YamlObject::points(std::string_view key,
                                                                     std::size_t minCount) {
  if (!has(key)) return std::nullopt;
  return pointsIn(at(key), key, minCount);
}

std::optional<std::vector<std::vector<std::array<double, 2>>>> YamlObject::pointLists(
    std::string_view key, std::size_t minCount) {
  if (!has(key)) return std::nullopt;
  const YAML::Node list = at(key);
  // [[x, y], ...] is one list; [[[x, y], ...], ...] several.
  const bool several = list.IsSequence() && list.size() > 0 && list[0].IsSequence() &&
                       list[0].size() > 0 && list[0][0].IsSequence();
  if (!several) {
    auto one = pointsIn(list, key, minCount);
    if (!one) return std::nullopt;
    return std::vector<std::vector<std::array<double, 2>>>{std::move(*one)};
  }
  std::vector<std::vector<std::array<double, 2>>> result;
  for (const auto& item : list) {
    auto points = pointsIn(item, key, minCount);
    if (!points) return std::nullopt;
    result.push_back(std::move(*points));
  }
  return result;
}

std::optional<std::vector<std::array<double, 2>>> YamlObject::pointsIn(const YAML::Node& list,
                                                                       std::string_view key,
                                                                       std::size_t minCount) {
  const std::string expected =
      fmt::format("a list of at least {} [x, y] pairs of numbers", minCount);
  if (!list.IsSequence() || list.size() < minCount) {
    diag_->error(
        file_, list.Mark(), childPath(key),
        fmt::format("expected {}, got {}", expected,
                    list.IsSequence() ? fmt::format("{} items", list.size()) : describe(list)));
    return std::nullopt;
  }
  std::vector<std::array<double, 2>> result;
  for (const auto& item : list) {
    std::array<double, 2> point{};
    const bool pair = item.IsSequence() && item.size() == 2 && item[0].IsScalar() &&
                      item[1].IsScalar() && YAML::convert<double>::decode(item[0], point[0]) &&
                      YAML::convert<double>::decode(item[1], point[1]) && std::isfinite(point[0]) &&
                      std::isfinite(point[1]);
    if (!pair) {
      diag_->error(file_, item.Mark(), childPath(key),
                   fmt::format("expected {}, got {}", expected, describe(item)));
      return std::nullopt;
    }
    result.push_back(point);
  }
  return result;
}

std::optional<std::string> YamlObject::choiceText(std::string_view key,
                                                  const std::vector<std::string_view>& names) {
  std::string expected = "one of";
  for (const auto name : names) expected += fmt::format(" '{}'", name);
  const auto value = scalar(key, expected);
  if (!value) return std::nullopt;
  if (std::find(names.begin(), names.end(), value->Scalar()) == names.end()) {
    error(key, fmt::format("expected {}, got {}", expected, describe(*value)));
    return std::nullopt;
  }
  return value->Scalar();
}

std::optional<std::filesystem::path> YamlObject::outputPath(std::string_view key) {
  const auto text = requiredString(key);
  if (!text) return std::nullopt;
  const std::filesystem::path path(*text);
  return path.is_absolute() ? path : file_.parent_path() / path;
}

std::optional<std::filesystem::path> YamlObject::existingFile(std::string_view key) {
  auto path = outputPath(key);
  if (!path) return std::nullopt;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(*path, ec)) {
    error(key,
          fmt::format("expected an existing file, got '{}' ({})", path->string(),
                      std::filesystem::exists(*path, ec) ? "not a regular file" : "no such file"));
    return std::nullopt;
  }
  return path;
}

std::optional<YamlObject> YamlObject::object(std::string_view key) {
  if (!has(key)) return std::nullopt;
  return YamlObject(at(key), childPath(key), file_, *diag_);
}

std::vector<YamlObject> YamlObject::objectList(std::string_view key, std::size_t minCount,
                                               std::size_t maxCount) {
  std::vector<YamlObject> items;
  const std::string expected = fmt::format("a list of {} to {} maps", minCount, maxCount);
  if (!has(key)) {
    if (minCount > 0) errorHere(fmt::format("missing key '{}' ({})", key, expected));
    return items;
  }
  YAML::Node list = at(key);
  if (!list.IsSequence() || list.size() < minCount || list.size() > maxCount) {
    error(key,
          fmt::format("expected {}, got {}", expected,
                      list.IsSequence() ? fmt::format("{} items", list.size()) : describe(list)));
    return items;
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    items.emplace_back(list[i], fmt::format("{}[{}]", childPath(key), i), file_, *diag_);
  }
  return items;
}

void YamlObject::finish() {
  if (!node_.IsMap()) return;
  std::set<std::string, std::less<>> seen;
  for (const auto& entry : node_) {
    const std::string name = entry.first.Scalar();
    if (!seen.insert(name).second) {
      diag_->error(file_, entry.first.Mark(), childPath(name), "duplicate key");
    } else if (!known_.contains(name)) {
      std::string expected;
      for (const auto& known : known_) expected += (expected.empty() ? "" : ", ") + known;
      diag_->error(file_, entry.first.Mark(), childPath(name),
                   fmt::format("unknown key (expected one of: {})", expected));
    }
  }
}

}  // namespace surroundd::daemon
