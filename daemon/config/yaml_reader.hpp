#pragma once
// Validating reads from yaml-cpp nodes, with error messages that say where and what.
//
// Every problem becomes one line "<file>:<line>:<column>: <key.path>: <what was expected>, got
// <what>" in a Diagnostics list; reading goes on with the default so that one run reports every
// error. ConfigLoader throws ConfigError with all of them at the end (the start-up boundary),
// before any device or output is opened.

#include <array>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <optional>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace surroundd::daemon {

class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(std::vector<std::string> messages);
  const std::vector<std::string>& messages() const { return messages_; }

 private:
  std::vector<std::string> messages_;
};

class Diagnostics {
 public:
  void error(const std::filesystem::path& file, const YAML::Mark& mark, std::string_view keyPath,
             std::string_view message);
  void add(std::string message) { messages_.push_back(std::move(message)); }
  bool empty() const { return messages_.empty(); }
  const std::vector<std::string>& messages() const { return messages_; }
  void throwIfAny() const;

 private:
  std::vector<std::string> messages_;
};

// Parses a YAML file; a syntax error or a missing/unreadable file becomes a ConfigError at once.
YAML::Node parseYamlFile(const std::filesystem::path& file);
// The same for text already read; `file` is what messages name.
YAML::Node parseYamlText(const std::string& text, const std::filesystem::path& file);

struct NumberRange {
  double min = -1e300;
  double max = 1e300;
  bool minExclusive = false;
  std::string_view unit;  // shown in messages, e.g. "pixels"
};

// One YAML mapping being read. Each accessor marks its key as known; finish() reports the keys that
// no accessor asked for (typos such as "fov_dg") and duplicates.
class YamlObject {
 public:
  YamlObject(const YAML::Node& node, std::string keyPath, std::filesystem::path file,
             Diagnostics& diag);

  bool has(std::string_view key);  // marks the key as known
  double number(std::string_view key, double fallback, const NumberRange& range = {});
  std::optional<double> requiredNumber(std::string_view key, const NumberRange& range = {});
  int integer(std::string_view key, int fallback, int min, int max);
  std::optional<int> requiredInteger(std::string_view key, int min, int max);
  bool boolean(std::string_view key, bool fallback);
  std::string string(std::string_view key, std::string fallback);
  std::optional<std::string> requiredString(std::string_view key);
  // A list of numbers whose length is one of `sizes`.
  std::optional<std::vector<double>> numbers(std::string_view key,
                                             std::initializer_list<std::size_t> sizes);
  // A list of minSize to maxSize numbers.
  std::optional<std::vector<double>> numbers(std::string_view key, std::size_t minSize,
                                             std::size_t maxSize);
  // A list of minSize to maxSize non-empty strings.
  std::optional<std::vector<std::string>> strings(std::string_view key, std::size_t minSize,
                                                  std::size_t maxSize);
  // A list of [x, y] pairs, at least `minCount` of them (a polygon).
  std::optional<std::vector<std::array<double, 2>>> points(std::string_view key,
                                                           std::size_t minCount);
  // One such list, or a list of them (polygons): each at least `minCount` pairs.
  std::optional<std::vector<std::vector<std::array<double, 2>>>> pointLists(std::string_view key,
                                                                            std::size_t minCount);

  template <class E>
  E choice(std::string_view key, E fallback,
           std::span<const std::pair<std::string_view, E>> options);
  template <class E>
  E choice(std::string_view key, E fallback,
           std::initializer_list<std::pair<std::string_view, E>> options) {
    return choice(key, fallback, std::span(options.begin(), options.size()));
  }

  // Paths are resolved against the directory of the file that names them.
  std::optional<std::filesystem::path> existingFile(std::string_view key);
  std::optional<std::filesystem::path> outputPath(std::string_view key);

  std::optional<YamlObject> object(std::string_view key);
  std::vector<YamlObject> objectList(std::string_view key, std::size_t minCount,
                                     std::size_t maxCount);

  // Reports unknown and duplicate keys. Call once when every known key has been read.
  void finish();

  const std::string& keyPath() const { return keyPath_; }
  const std::filesystem::path& file() const { return file_; }
  const YAML::Mark& mark() const { return mark_; }
  Diagnostics& diagnostics() { return *diag_; }
  void error(std::string_view key, std::string_view message);  // at the key (or this map if absent)
  void errorHere(std::string_view message);                    // at this map itself

 private:
  // Const lookup: yaml-cpp's non-const operator[] would insert the key.
  YAML::Node at(std::string_view key) const {
    const YAML::Node& map = node_;
    return map[std::string(key)];
  }
  std::optional<YAML::Node> scalar(std::string_view key, std::string_view expected);
  std::string childPath(std::string_view key) const;
  // points()'s reading of `list`, found at `key`.
  std::optional<std::vector<std::array<double, 2>>> pointsIn(const YAML::Node& list,
                                                             std::string_view key,
                                                             std::size_t minCount);
  YAML::Mark markOf(std::string_view key) const;
  std::optional<std::vector<double>> numberList(std::string_view key, const std::string& expected,
                                                const std::function<bool(std::size_t)>& sizeFits);
  std::optional<std::string> choiceText(std::string_view key,
                                        const std::vector<std::string_view>& names);

  YAML::Node node_;
  std::string keyPath_;
  std::filesystem::path file_;
  Diagnostics* diag_;
  YAML::Mark mark_;
  std::set<std::string, std::less<>> known_;
};

template <class E>
E YamlObject::choice(std::string_view key, E fallback,
                     std::span<const std::pair<std::string_view, E>> options) {
  std::vector<std::string_view> names;
  for (const auto& option : options) names.push_back(option.first);
  const auto text = choiceText(key, names);
  if (!text) return fallback;
  for (const auto& [name, value] : options) {
    if (*text == name) return value;
  }
  return fallback;
}

}  // namespace surroundd::daemon
