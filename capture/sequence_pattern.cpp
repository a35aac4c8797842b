#include "capture/sequence_pattern.hpp"

#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <vector>

extern "C" {
#include <libavformat/avformat.h>
}

namespace surroundd::capture {

FileNameKind classifyFileName(std::string_view path) {
  int conversions = 0;
  bool tooWide = false;
  for (std::size_t at = path.find('%'); at != std::string_view::npos; at = path.find('%', at + 1)) {
    std::size_t end = at + 1;
    int width = 0;
    while (end < path.size() && std::isdigit(static_cast<unsigned char>(path[end])) != 0) {
      // Saturates: only whether it passes kMaxSequenceDigits matters.
      width = std::min(width * 10 + (path[end] - '0'), kMaxSequenceDigits + 1);
      ++end;
    }
    if (end == path.size()) return FileNameKind::kPlainFile;
    if (path[end] == '%') {
      at = end;  // "%%": a literal '%'
      continue;
    }
    if (path[end] != 'd') return FileNameKind::kPlainFile;
    ++conversions;
    tooWide = tooWide || width > kMaxSequenceDigits;
    at = end;
  }
  if (conversions != 1) return FileNameKind::kPlainFile;
  return tooWide ? FileNameKind::kTooWide : FileNameKind::kSequence;
}

std::string sequenceFrameName(std::string_view pattern, int index) {
  if (classifyFileName(pattern) != FileNameKind::kSequence) {
    throw std::invalid_argument("not an image sequence pattern: " + std::string(pattern));
  }
  const std::string terminated(pattern);
  std::vector<char> name(terminated.size() + kMaxSequenceDigits + 16, '\0');
  if (av_get_frame_filename2(name.data(), static_cast<int>(name.size()), terminated.c_str(), index,
                             0) < 0) {
    throw std::invalid_argument("FFmpeg refuses the image sequence pattern " + terminated);
  }
  return name.data();
}

}  // namespace surroundd::capture
