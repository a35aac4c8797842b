#include "common/nesting_depth.hpp"

#include <algorithm>

namespace surroundd {

std::size_t nestingDepth(std::string_view text) {
  // Closers are counted as they come, but the deepest level reached is what a recursive parser
  // needs stack for; `level` never goes below zero, so "]]][[[" still counts 3.
  std::size_t level = 0;
  std::size_t deepest = 0;
  bool inString = false;
  const auto open = [&] { deepest = std::max(deepest, ++level); };
  const auto close = [&] { level -= level > 0 ? 1 : 0; };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (inString) {
      if (c == '\\') {
        ++i;  // the escaped character, whatever it is
      } else if (c == '"' || c == '\n') {
        inString = false;
      }
      continue;
    }
    const char next = i + 1 < text.size() ? text[i + 1] : '\0';
    switch (c) {
      case '"':
        inString = true;
        break;
      case '[':
      case '{':
        open();
        break;
      case ']':
      case '}':
        close();
        break;
      case '<':
        if (next == '/') {
          close();
        } else if ((next >= 'a' && next <= 'z') || (next >= 'A' && next <= 'Z') || next == '_') {
          open();
        }
        break;
      case '/':
        if (next == '>') close();
        break;
      default:
        break;
    }
  }
  return deepest;
}

}  // namespace surroundd
