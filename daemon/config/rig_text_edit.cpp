#include "daemon/config/rig_text_edit.hpp"

#include <algorithm>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

namespace surroundd::daemon {
namespace {

// Just past the flow collection ('{' or '[') that starts at `begin`. Quoted strings are skipped
// where a scalar can start (after a bracket, a comma, a colon or a blank: "O'Neil" is plain), and
// so are comments (a '#' after a blank, to the end of its line).
std::size_t flowEnd(const std::string& text, std::size_t begin) {
  int depth = 0;
  char quote = 0;
  char before = ' ';  // the character before the one read, outside quotes
  for (std::size_t i = begin; i < text.size(); ++i) {
    const char c = text[i];
    if (quote != 0) {
      if (c == '\\' && quote == '"') {
        ++i;
      } else if (c == quote) {
        quote = 0;
        before = c;
      }
      continue;
    }
    const bool scalarStart = before == '{' || before == '[' || before == ',' || before == ':' ||
                             before == ' ' || before == '\t' || before == '\n';
    if ((c == '"' || c == '\'') && scalarStart) {
      quote = c;
    } else if (c == '#' && (before == ' ' || before == '\t' || before == '\n')) {
      i = std::min(text.find('\n', i), text.size()) - 1;
      before = '\n';
      continue;
    } else if (c == '{' || c == '[') {
      ++depth;
    } else if ((c == '}' || c == ']') && --depth == 0) {
      return i + 1;
    }
    before = c;
  }
  throw std::invalid_argument("a flow collection that does not end");
}

// The end of a block value that ends where the next node (at `next`) begins: the end of the last
// line before `next` that holds more than blanks or a comment (that line's comments are the
// value's; the lines between belong to what follows).
std::size_t blockEnd(const std::string& text, std::size_t begin, std::size_t next) {
  // The end of the text ends a line too, when the file has no newline at its end.
  std::size_t end = next == text.size() && !text.ends_with('\n')
                        ? text.size()
                        : text.rfind('\n', next > 0 ? next - 1 : 0);
  if (end == std::string::npos || end < begin) return next;
  while (end > begin) {
    const std::size_t lineStart = text.rfind('\n', end - 1);
    const std::size_t from = lineStart == std::string::npos ? 0 : lineStart + 1;
    const auto line = std::string_view(text).substr(from, end - from);
    const auto first = line.find_first_not_of(" \t\r");
    if (first != std::string_view::npos && line[first] != '#') return end;
    if (from <= begin) return end;
    end = from - 1;
  }
  return end;
}

// Past a comment that follows `end` on its line ("  # ..."), if there is one.
std::size_t withTrailingComment(const std::string& text, std::size_t end) {
  std::size_t at = end;
  while (at < text.size() && (text[at] == ' ' || text[at] == '\t')) ++at;
  if (at < text.size() && text[at] == '#') return std::min(text.find('\n', at), text.size());
  return end;
}

struct Splice {
  std::size_t begin = 0, end = 0;
  std::string with;
};

}  // namespace

std::string editRigText(const std::string& text, const std::string& key,
                        std::span<const RigTextEdit> edits, std::string_view comment) {
  const YAML::Node document = YAML::Load(text);
  const YAML::Node cameras = document["cameras"];
  if (!document.IsMap() || !cameras.IsSequence()) {
    throw std::invalid_argument("the rig has no list of cameras");
  }
  // Where the next node after the camera list starts: the top-level key after `cameras`.
  std::size_t afterCameras = text.size();
  bool passed = false;
  for (const auto& top : document) {
    if (passed) {
      afterCameras = top.first.Mark().pos;
      break;
    }
    passed = top.first.Scalar() == "cameras";
  }
  const std::string note = comment.empty() ? "" : fmt::format("  # {}", comment);
  std::vector<Splice> splices;
  for (const auto& edit : edits) {
    std::size_t index = 0;
    while (index < cameras.size() && !(cameras[index].IsMap() && cameras[index]["name"] &&
                                       cameras[index]["name"].Scalar() == edit.camera)) {
      ++index;
    }
    if (index == cameras.size()) {
      throw std::invalid_argument(fmt::format("no camera '{}'", edit.camera));
    }
    const YAML::Node entry = cameras[index];
    const std::size_t nextEntry =
        index + 1 < cameras.size() ? cameras[index + 1].Mark().pos : afterCameras;
    const bool flowEntry = entry.Style() == YAML::EmitterStyle::Flow;
    // The value's start, and where the node after it starts.
    std::optional<std::size_t> begin;
    std::size_t next = nextEntry;
    for (auto field = entry.begin(); field != entry.end(); ++field) {
      if (field->first.Scalar() != key) continue;
      begin = field->second.Mark().pos;
      if (auto following = std::next(field); following != entry.end()) {
        next = following->first.Mark().pos;
      }
    }
    if (begin) {
      const YAML::Node value = entry[key];
      if (!value.IsMap()) {
        throw std::invalid_argument(
            fmt::format("camera '{}': its {} is not a map", edit.camera, key));
      }
      const bool flow = value.Style() == YAML::EmitterStyle::Flow;
      std::size_t end = flow ? flowEnd(text, *begin) : blockEnd(text, *begin, next);
      // A comment after the old value's last line was about the old value; inside a flow entry
      // the value does not end its line.
      const bool endsLine = !flowEntry;
      if (endsLine) end = withTrailingComment(text, end);
      splices.push_back({*begin, end, edit.flowValue + (endsLine ? note : "")});
    } else if (flowEntry) {
      const std::size_t close = flowEnd(text, entry.Mark().pos) - 1;  // the entry's '}'
      splices.push_back({close, close, fmt::format(", {}: {}", key, edit.flowValue)});
    } else {
      // A line of its own after the entry's last, at the column of its keys.
      const std::size_t last = blockEnd(text, entry.Mark().pos, nextEntry);
      const std::string indent(entry.begin()->first.Mark().column, ' ');
      splices.push_back(
          {last, last, fmt::format("\n{}{}: {}{}", indent, key, edit.flowValue, note)});
    }
  }
  // From the end of the text back, so that each splice's positions still hold.
  std::ranges::sort(splices, [](const Splice& a, const Splice& b) { return a.begin > b.begin; });
  std::string edited = text;
  for (const auto& splice : splices) {
    edited.replace(splice.begin, splice.end - splice.begin, splice.with);
  }
  return edited;
}

}  // namespace surroundd::daemon
