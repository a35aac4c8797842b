#pragma once
// A config section's keys as one table: each row names a key, the field it sets, its kind with its
// range and unit (or its choices) and a one-line doc. The loader reads a section by walking its
// table, the range and unit make its error messages, and the reference config
// (config/surroundd.reference.yaml) is tested against the tables: every key there, in its section,
// at its default, with the doc and the range in its comment (tests/daemon/reference_config_test).
//
// The default is the field's initialiser (config.hpp): a row names the field, never a copy of the
// value. Rules across keys (one below another, even sizes) stay named checks after the walk.

#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "daemon/config/yaml_reader.hpp"

namespace surroundd::daemon {

// What the reference config shows as a key's value.
enum class Shown {
  kDefault,  // the default: the field's initialiser
  kExample,  // an example: the key is required, or its default is worked out (from the vehicle,
             // the run's environment, the keys before it) and the reference says how
};

// A key as the reference test sees it, whatever its section's struct.
struct KeyDoc {
  std::string_view name;
  std::string_view doc;
  // What the reference's comment on the key names too: its range ("0..1000") or its choices.
  std::vector<std::string> terms;
  Shown shown = Shown::kDefault;
  // Reads the key from `object` into a default section: whether it reads as the default.
  std::function<bool(YamlObject& object)> readsAsDefault;
};

// The field of a member of a member: nested(&RenderConfig::views, &ViewSettings::topRangeM) (a
// fold of `.*` over the members).
template <class... Members>
constexpr auto nested(Members... members) {
  return [=](auto& section) -> auto& { return (section.*....*members); };
}

// "0..1000": a range as the reference writes it (whole numbers in full, not as 1e+07).
inline std::string rangeTerm(double min, double max) {
  const auto plain = [](double v) {
    return v == std::trunc(v) && std::abs(v) < 1e15 ? fmt::format("{}", static_cast<long long>(v))
                                                    : fmt::format("{:g}", v);
  };
  return fmt::format("{}..{}", plain(min), plain(max));
}

// One row of a table over `Section`; made by the builders below.
template <class Section>
struct ConfigKey {
  std::string_view name;
  std::string_view doc;  // one line: the reference's comment on the key contains it
  std::vector<std::string> terms;
  Shown shown = Shown::kDefault;
  // Reads the key into the section, the field's value as the fallback; problems go to `object`.
  std::function<void(YamlObject& object, Section& section)> read;
  // Whether two sections hold the same value of the key.
  std::function<bool(const Section& a, const Section& b)> same;

  // The type of the field `field` (a member pointer or nested()) names.
  template <class Field>
  using FieldOf = std::remove_cvref_t<std::invoke_result_t<const Field&, Section&>>;
  template <class Field>
  using Choices = std::span<const std::pair<std::string_view, FieldOf<Field>>>;

  template <class Field>
  static ConfigKey number(std::string_view name, Field field, NumberRange range,
                          std::string_view doc, Shown shown = Shown::kDefault) {
    return make(name, field, doc, {numberTerm(name, range)}, shown, [=](YamlObject& o, Section& s) {
      auto& value = std::invoke(field, s);
      value = o.number(name, value, range);
    });
  }
  // A number whose default follows the keys read before it (`fallback` of the section so far).
  template <class Field>
  static ConfigKey derivedNumber(std::string_view name, Field field,
                                 double (*fallback)(const Section&), NumberRange range,
                                 std::string_view doc) {
    return make(name, field, doc, {numberTerm(name, range)}, Shown::kExample,
                [=](YamlObject& o, Section& s) {
                  std::invoke(field, s) = o.number(name, fallback(s), range);
                });
  }
  template <class Field>
  static ConfigKey integer(std::string_view name, Field field, int min, int max,
                           std::string_view doc) {
    return make(name, field, doc, {rangeTerm(min, max)}, Shown::kDefault,
                [=](YamlObject& o, Section& s) {
                  auto& value = std::invoke(field, s);
                  value = o.integer(name, value, min, max);
                });
  }
  // Whole milliseconds into a std::chrono::milliseconds field.
  template <class Field>
  static ConfigKey milliseconds(std::string_view name, Field field, int min, int max,
                                std::string_view doc) {
    return make(
        name, field, doc, {rangeTerm(min, max)}, Shown::kDefault, [=](YamlObject& o, Section& s) {
          auto& value = std::invoke(field, s);
          value =
              std::chrono::milliseconds(o.integer(name, static_cast<int>(value.count()), min, max));
        });
  }
  // Seconds, any number in `range`, into a std::chrono::milliseconds field.
  template <class Field>
  static ConfigKey seconds(std::string_view name, Field field, NumberRange range,
                           std::string_view doc) {
    return make(
        name, field, doc, {numberTerm(name, range)}, Shown::kDefault,
        [=](YamlObject& o, Section& s) {
          auto& value = std::invoke(field, s);
          const double fallback = static_cast<double>(value.count()) / 1000;
          value = std::chrono::milliseconds(std::lround(1000 * o.number(name, fallback, range)));
        });
  }
  template <class Field>
  static ConfigKey choice(std::string_view name, Field field, Choices<Field> options,
                          std::string_view doc, Shown shown = Shown::kDefault) {
    std::vector<std::pair<std::string_view, FieldOf<Field>>> kept(options.begin(), options.end());
    std::vector<std::string> names;
    names.reserve(kept.size());
    for (const auto& option : kept) names.emplace_back(option.first);
    return make(name, field, doc, std::move(names), shown, [=](YamlObject& o, Section& s) {
      auto& value = std::invoke(field, s);
      value = o.choice(name, value, Choices<Field>(kept));
    });
  }
  template <class Field>
  static ConfigKey choice(
      std::string_view name, Field field,
      std::initializer_list<std::pair<std::string_view, FieldOf<Field>>> options,
      std::string_view doc, Shown shown = Shown::kDefault) {
    return choice(name, field, Choices<Field>(options.begin(), options.size()), doc, shown);
  }
  template <class Field>
  static ConfigKey flag(std::string_view name, Field field, std::string_view doc) {
    return make(name, field, doc, {}, Shown::kDefault, [=](YamlObject& o, Section& s) {
      auto& value = std::invoke(field, s);
      value = o.boolean(name, value);
    });
  }
  // A non-empty string, taken as written (a path too: a device is not relative to the file).
  template <class Field>
  static ConfigKey text(std::string_view name, Field field, std::string_view doc,
                        Shown shown = Shown::kDefault) {
    return make(name, field, doc, {}, shown, [=](YamlObject& o, Section& s) {
      auto& value = std::invoke(field, s);
      value = o.string(name, std::string(value));
    });
  }
  // A list of minSize to maxSize non-empty strings.
  template <class Field>
  static ConfigKey names(std::string_view name, Field field, std::size_t minSize,
                         std::size_t maxSize, std::string_view doc) {
    return make(name, field, doc, {}, Shown::kDefault, [=](YamlObject& o, Section& s) {
      auto& value = std::invoke(field, s);
      if (auto read = o.strings(name, minSize, maxSize)) value = std::move(*read);
    });
  }
  // A path relative to the config's folder, required where its section is given.
  template <class Field>
  static ConfigKey requiredPath(std::string_view name, Field field, std::string_view doc) {
    return make(name, field, doc, {}, Shown::kExample, [=](YamlObject& o, Section& s) {
      std::invoke(field, s) = o.outputPath(name).value_or("");
    });
  }
  template <class Field>
  static ConfigKey optionalPath(std::string_view name, Field field, std::string_view doc) {
    return make(name, field, doc, {}, Shown::kExample, [=](YamlObject& o, Section& s) {
      if (o.has(name)) std::invoke(field, s) = o.outputPath(name).value_or("");
    });
  }
  // A key no builder above reads: its own reader and comparison.
  static ConfigKey custom(std::string_view name, std::string_view doc,
                          std::function<void(YamlObject&, Section&)> read,
                          std::function<bool(const Section&, const Section&)> same,
                          std::vector<std::string> terms = {}, Shown shown = Shown::kDefault) {
    return {name, doc, std::move(terms), shown, std::move(read), std::move(same)};
  }

 private:
  template <class Field>
  static ConfigKey make(std::string_view name, Field field, std::string_view doc,
                        std::vector<std::string> terms, Shown shown,
                        std::function<void(YamlObject&, Section&)> read) {
    return {name,
            doc,
            std::move(terms),
            shown,
            std::move(read),
            [field](const Section& a, const Section& b) {
              return std::invoke(field, a) == std::invoke(field, b);
            }};
  }
  // "0..1000", or for a range open at its low end "0 < tolerance <= 0.5".
  static std::string numberTerm(std::string_view name, const NumberRange& range) {
    if (!range.minExclusive) return rangeTerm(range.min, range.max);
    return fmt::format("{:g} < {} <= {:g}", range.min, name, range.max);
  }
};

// A section's table: read() walks it in order.
template <class Section>
class ConfigKeys {
 public:
  ConfigKeys() = default;
  ConfigKeys(std::initializer_list<ConfigKey<Section>> keys) : keys_(keys) {}
  explicit ConfigKeys(std::vector<ConfigKey<Section>> keys) : keys_(std::move(keys)) {}

  void read(YamlObject& object, Section& section) const {
    for (const auto& key : keys_) key.read(object, section);
  }

  std::vector<KeyDoc> docs() const {
    std::vector<KeyDoc> docs;
    docs.reserve(keys_.size());
    for (const auto& key : keys_) {
      docs.push_back({key.name, key.doc, key.terms, key.shown, [key](YamlObject& object) {
                        Section read{};
                        key.read(object, read);
                        return key.same(read, Section{});
                      }});
    }
    return docs;
  }

 private:
  std::vector<ConfigKey<Section>> keys_;
};

}  // namespace surroundd::daemon
