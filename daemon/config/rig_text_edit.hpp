#pragma once
// One key (lens: or mount:) of named cameras replaced in a rig file's text, and nothing else
// touched: every other byte — comments anywhere, the order of keys, flow or block style, keys of
// the user's own, other cameras — stays as it was written. The new value is a flow map on the
// line of the old one, with a comment after it; a camera without the key gets it as a line of its
// own after its last one (inside a flow entry, as its last pair). The text is read with yaml-cpp
// only to find where each value lies (its marks); it is never emitted again.
//
// Error policy: std::invalid_argument naming the camera when the text has no such camera, or its
// entry or value is not one that can be edited in place (not a map).

#include <span>
#include <string>
#include <string_view>

namespace surroundd::daemon {

struct RigTextEdit {
  std::string camera;     // its `name:`
  std::string flowValue;  // the new value, "{x_m: 1, ...}"
};

// `text` with `key` of each edit's camera replaced by its value, followed by "  # comment" where
// the value ends a line (`comment` on one line).
std::string editRigText(const std::string& text, const std::string& key,
                        std::span<const RigTextEdit> edits, std::string_view comment);

}  // namespace surroundd::daemon
