#pragma once
// What a file name with a '%' in it is to FFmpeg's image2 demuxer, decided here once so that no
// caller hands a user's path to a printf-family call: one "%d" or "%0Nd" conversion makes it an
// image sequence ("front_%06d.png", "%%" for a literal '%'); anything else (a "%s", two "%d",
// "100%.png") makes it a plain file name, as image2 itself falls back to one.

#include <string>
#include <string_view>

namespace surroundd::capture {

enum class FileNameKind {
  kPlainFile,
  kSequence,
  kTooWide,  // a "%Nd" wider than kMaxSequenceDigits: formatting it would take gigabytes
};

inline constexpr int kMaxSequenceDigits = 32;

FileNameKind classifyFileName(std::string_view path);

// The file of frame `index` of a pattern that classifyFileName() calls kSequence (FFmpeg's own
// expansion, av_get_frame_filename2). Throws std::invalid_argument for any other path.
std::string sequenceFrameName(std::string_view pattern, int index);

}  // namespace surroundd::capture
