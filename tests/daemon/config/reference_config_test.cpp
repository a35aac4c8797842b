// The reference config against the key tables (daemon/config/config_sections.hpp and each output
// type's): every key of every table is in config/surroundd.reference.yaml under its section, with
// the table's doc and range (or choices) in its comment and, where the table shows a default, at
// that default; no key is there that the tables lack. Keys commented out count: they are how the
// reference shows a value worked out at run time. (ReferenceConfig.DocumentsTheDefaults, in
// config_test.cpp, loads the file whole.)

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

#include "daemon/config/config_sections.hpp"
#include "daemon/config/output_type.hpp"

namespace surroundd::daemon {
namespace {

// A key as the reference writes it, commented out or not.
struct ReferenceKey {
  std::string section;  // the top-level key it is under
  std::string block;    // under `outputs:`, the type of its entry
  std::string name;
  std::string value;
  std::string comment;  // above it, beside it and on the lines after, in one line
  int line = 0;
};

// The reference's comments beside values start this far right; a comment that starts further
// left is prose, or a key commented out.
constexpr std::size_t kBesideColumn = 16;

std::string squeezed(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == ' ' && (out.empty() || out.back() == ' ')) continue;
    out += c;
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

class ReferenceParser {
 public:
  std::vector<ReferenceKey> parse(const std::string& text) {
    std::istringstream lines(text);
    std::string line;
    while (std::getline(lines, line)) {
      ++number_;
      take(line);
    }
    return std::move(keys_);
  }

 private:
  void take(const std::string& line) {
    const auto start = line.find_first_not_of(' ');
    std::smatch match;
    if (start == std::string::npos) {
      above_.clear();
      last_.reset();
    } else if (start == 0 && std::regex_match(line, match, sectionLine_) &&
               !(match[1].matched && match[3].matched)) {
      section_ = match[2];
      block_.clear();
      above_.clear();
      last_.reset();
    } else if (line[start] != '#') {
      takeKey(line.substr(start));
    } else {
      takeComment(line, start);
    }
  }

  void takeComment(const std::string& line, std::size_t hash) {
    const auto textAt = line.find_first_not_of(' ', hash + 1);
    if (textAt == std::string::npos) return;
    const std::string text = line.substr(textAt);
    if (textAt >= kBesideColumn) {
      // A comment beside a key, continued (its '#' after the '#' of a block commented out).
      addToLast(text.starts_with('#') ? text.substr(1) : text);
    } else if (text.starts_with('#')) {
      takeComment(line, textAt);  // a key commented out inside a block commented out
    } else if (!takeKey(text)) {
      above_ += " " + text;
      last_.reset();
    }
  }

  void addToLast(std::string_view text) {
    if (last_) keys_[*last_].comment += " " + std::string(text);
  }

  bool takeKey(const std::string& text) {
    std::smatch match;
    if (section_.empty() || !std::regex_match(text, match, keyText_)) return false;
    ReferenceKey key{section_, block_, match[2], match[4], above_, number_};
    if (const auto hash = key.value.find(" #"); hash != std::string::npos) {
      key.comment += " " + key.value.substr(hash + 2);
      key.value = squeezed(key.value.substr(0, hash));
    }
    if (match[1].matched && key.name == "type") block_ = key.block = key.value;
    above_.clear();
    last_ = keys_.size();
    keys_.push_back(std::move(key));
    return true;
  }

  // A top-level key at column 0, or one commented out with nothing beside it.
  const std::regex sectionLine_{R"(^(# )?([a-z_]+):\s*(#.*)?$)"};
  // A key, commented out or not, maybe the first of a list entry ("- type: video").
  const std::regex keyText_{R"(^(- )?([a-z_][a-z0-9_]*):(\s+(.*))?$)"};
  std::vector<ReferenceKey> keys_;
  std::string section_, block_, above_;
  std::optional<std::size_t> last_;
  int number_ = 0;
};

std::vector<ReferenceKey> referenceKeys() {
  std::ifstream file(std::filesystem::path(SURROUNDD_SOURCE_DIR) /
                     "config/surroundd.reference.yaml");
  const std::string text{std::istreambuf_iterator<char>(file), {}};
  EXPECT_FALSE(text.empty());
  auto keys = ReferenceParser().parse(text);
  for (auto& key : keys) key.comment = squeezed(key.comment);
  return keys;
}

std::string where(const ReferenceKey& key) {
  return "surroundd.reference.yaml:" + std::to_string(key.line) + ": " + key.section + "." +
         key.name;
}

// Its doc and terms (range, choices) in the comment of `key`.
bool documents(const ReferenceKey& key, const KeyDoc& doc) {
  if (key.comment.find(doc.doc) == std::string::npos) return false;
  return std::ranges::all_of(doc.terms, [&](const std::string& term) {
    return key.comment.find(term) != std::string::npos;
  });
}

void expectDocumented(const ReferenceKey& key, const KeyDoc& doc) {
  EXPECT_TRUE(documents(key, doc))
      << where(key) << ": the comment does not say '" << doc.doc << "' and "
      << ::testing::PrintToString(doc.terms) << ": '" << key.comment << "'";
}

// A key the table shows at its default: its value reads as the field's initialiser.
void expectDefault(const ReferenceKey& key, const KeyDoc& doc) {
  if (doc.shown != Shown::kDefault) return;
  Diagnostics diag;
  YamlObject object(YAML::Load(key.name + ": " + key.value), key.section, "reference", diag);
  const bool isDefault = doc.readsAsDefault(object);
  EXPECT_TRUE(diag.empty()) << where(key) << ": " << ::testing::PrintToString(diag.messages());
  EXPECT_TRUE(isDefault) << where(key) << ": '" << key.value << "' is not the default";
}

const KeyDoc* find(const std::vector<KeyDoc>& docs, std::string_view name) {
  const auto found = std::ranges::find(docs, name, &KeyDoc::name);
  return found == docs.end() ? nullptr : &*found;
}

TEST(ReferenceConfig, DocumentsEveryKeyOfEverySection) {
  const auto keys = referenceKeys();
  for (const ConfigSection& section : configSections()) {
    const std::vector<KeyDoc> docs = section.docs();
    for (const KeyDoc& doc : docs) {
      const auto key = std::ranges::find_if(keys, [&](const ReferenceKey& k) {
        return k.section == section.name && k.name == doc.name;
      });
      if (key == keys.end()) {
        ADD_FAILURE() << section.name << "." << doc.name << " is not in the reference";
        continue;
      }
      expectDocumented(*key, doc);
      expectDefault(*key, doc);
    }
    for (const auto& key : keys) {
      if (key.section != section.name) continue;
      EXPECT_NE(find(docs, key.name), nullptr) << where(key) << ": no such key";
    }
  }
}

// The sections the reference documents are those the reader reads, from the one list they both
// walk (configSections()), with the rig and the outputs, which have tables of their own.
TEST(ReferenceConfig, DocumentsOnlySectionsTheReaderReads) {
  std::vector<std::string_view> read{"rig", "outputs"};
  for (const ConfigSection& section : configSections()) read.push_back(section.name);
  for (const ReferenceKey& key : referenceKeys()) {
    EXPECT_NE(std::ranges::find(read, key.section), read.end())
        << where(key) << ": a section the reader does not read";
  }
}

// An output type's keys in the reference's entry of that type, each documented there or where an
// entry before it has the same key (the encoder's keys are told once, for video). Types this build
// leaves out have no table to hold their entries against.
TEST(ReferenceConfig, DocumentsEveryOutputTypesKeys) {
  const auto keys = referenceKeys();
  const auto common = outputKeys().docs();
  const auto documentedUpTo = [&](const ReferenceKey& at, const KeyDoc& doc) {
    return std::ranges::any_of(keys, [&](const ReferenceKey& k) {
      return k.section == "outputs" && k.name == doc.name && k.line <= at.line && documents(k, doc);
    });
  };
  for (const std::string_view name : outputTypeNames()) {
    const OutputType& type = *findOutputType(name);
    if (!type.leftOut.empty()) continue;
    const auto docs = ownKeyDocs(type);
    std::vector<ReferenceKey> entry;
    std::ranges::copy_if(keys, std::back_inserter(entry), [&](const ReferenceKey& k) {
      return k.section == "outputs" && k.block == name;
    });
    EXPECT_FALSE(entry.empty()) << "no output of type '" << name << "' in the reference";
    for (const KeyDoc& doc : docs) {
      const auto key = std::ranges::find(entry, doc.name, &ReferenceKey::name);
      if (key == entry.end()) {
        ADD_FAILURE() << "the reference's '" << name << "' output has no '" << doc.name << "'";
        continue;
      }
      EXPECT_TRUE(documentedUpTo(*key, doc)) << where(*key) << ": '" << doc.doc << "' and "
                                             << ::testing::PrintToString(doc.terms) << " untold";
      expectDefault(*key, doc);
    }
    for (const auto& key : entry) {
      EXPECT_TRUE(key.name == "type" || find(docs, key.name) || find(common, key.name))
          << where(key) << ": a '" << name << "' output has no such key";
    }
  }
}

// `stream` and `view`, which every output has: told at their first entry.
TEST(ReferenceConfig, DocumentsTheKeysEveryOutputHas) {
  const auto keys = referenceKeys();
  for (const KeyDoc& doc : outputKeys().docs()) {
    const auto key = std::ranges::find_if(
        keys, [&](const ReferenceKey& k) { return k.section == "outputs" && k.name == doc.name; });
    if (key == keys.end()) {
      ADD_FAILURE() << "outputs: no entry has '" << doc.name << "'";
      continue;
    }
    expectDocumented(*key, doc);
    expectDefault(*key, doc);
  }
  for (const auto& key : keys) {
    if (key.section == "outputs") {
      EXPECT_NE(findOutputType(key.block), nullptr) << where(key) << ": no such output type";
    }
  }
}

}  // namespace
}  // namespace surroundd::daemon
