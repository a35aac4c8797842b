#pragma once
// The files a config's outputs write, and the rule that no run destroys another's data.
//
//  - Two outputs of one config never write the same file: not by the same path, not through a
//    symlink, not a plain video named like another output's segments, not inside a recording's
//    folder. What each output's path is comes from its type (OutputPathUse, output_type.hpp).
//    outputFileClash() says which; the config loader refuses such a config (so does
//    --check-config).
//  - A run never overwrites what an earlier one wrote: where a video's file, the .part file a
//    killed run left (its frames can still be recovered), or a recording's folder already holds
//    data, this run writes <stem>-N<ext> instead, N one past the highest present
//    (unusedOutputPath()); restarts and reloads alike, so numbers go on across processes in the
//    order the runs wrote them. A video's `keep_last` / `max_mb` then removes the lowest.
//  - Segments go on after the highest number present (render::VideoSink).
//  - A snapshot is the newest picture: each run replaces it (written whole, then renamed).

#include <filesystem>
#include <optional>
#include <string>

#include "daemon/config/config.hpp"

namespace surroundd::daemon {

// Why `a` and `b` (two outputs of one config) would write the same file, or nullopt.
std::optional<std::string> outputFileClash(const OutputConfig& a, const OutputConfig& b);

// The path this run writes `output` to: its own, or <stem>-N<ext> with N one past the highest
// present when its own holds data. Outputs without a file (or segmented ones, or snapshots) keep
// theirs.
std::filesystem::path unusedOutputPath(const OutputConfig& output);

// Creates `folder` for output `output`'s files; throws std::runtime_error naming both.
void createOutputFolder(const std::filesystem::path& folder, const std::filesystem::path& output);

}  // namespace surroundd::daemon
