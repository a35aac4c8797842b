#pragma once
// How deeply a text file's structure nests, found in one pass before a recursive parser reads it.
// tinygltf's JSON and OpenCV's FileStorage (YAML, JSON, XML) recurse once per level: 20 000
// nested '[' in a car model or 100 000 in an imported calibration overflowed the stack. A reader
// handed such a file refuses it here, naming the file, when it nests deeper than any real file of
// its kind does.

#include <cstddef>
#include <string_view>

namespace surroundd {

// The deepest nesting of `text`: brackets ('[' '{' opened, ']' '}' closed) outside double-quoted
// strings (which end at their closing quote, or at a line's end as JSON's must), and XML elements
// ('<' and a letter opened, "</" or "/>" closed). Counted as a parser that recurses would nest,
// never less: a stray closer does not lower the depth below what was opened before it.
std::size_t nestingDepth(std::string_view text);

}  // namespace surroundd
