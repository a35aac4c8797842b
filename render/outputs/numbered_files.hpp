#pragma once
// The files one video output writes over time beside its path: <stem><ext> and <stem>-N<ext> (the
// next run's file, or segment N), each also as the .part file it is written as (a killed run's
// holds frames too). New ones are numbered after the highest present, so numbers go in the order
// they were written; retention removes the lowest.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace surroundd::render {

struct NumberedFile {
  std::int64_t number = 0;  // 0: <stem><ext> itself
  std::filesystem::path path;
  std::uintmax_t bytes = 0;
};

// Numbers above this are refused rather than let to wrap (a stray "seg-9223372036854775807"):
// one that large counts as this.
inline constexpr std::int64_t kMaxFileNumber = 999'999'999'999;

// Those files present beside `path`, lowest number first (a number's .part file after it).
std::vector<NumberedFile> numberedFiles(const std::filesystem::path& path);

// How many of an output's files to keep, and how many bytes they may hold together; 0: no limit.
struct Retention {
  std::filesystem::path family;  // the output's configured path: its files are numberedFiles()
  int keepLast = 0;
  std::uint64_t maxBytes = 0;
  bool limits() const { return keepLast > 0 || maxBytes > 0; }
};

// "the newest 5, at most 100 MB together".
std::string describe(const Retention& retention);

// Removes the lowest-numbered of the family's files until at most `keepLast` are left and they
// hold at most `maxBytes`, `writing` (the file being written, kept whatever its size) among them.
// Returns what it removed; a file that cannot be removed is left and not counted as removed.
std::vector<std::filesystem::path> retainNewest(const Retention& retention,
                                                const std::filesystem::path& writing);

}  // namespace surroundd::render
