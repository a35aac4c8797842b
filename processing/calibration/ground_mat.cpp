#include "processing/calibration/ground_mat.hpp"

#include <algorithm>

namespace surroundd::processing {

BoardSymmetry symmetryOf(const Checkerboard& board) {
  const cv::Size inner = board.innerCorners;
  if (board.orientationIsUnambiguous()) return BoardSymmetry::kNone;
  // On a square board of n x n inner corners a quarter turn maps inner square (i, j) to
  // (j, n - 2 - i), changing the colour parity i + j by n - 2 - 2i: for odd n every square changes
  // colour and the turn shows, for even n none does.
  return inner.width == inner.height && inner.width % 2 == 0 ? BoardSymmetry::kQuarterTurn
                                                             : BoardSymmetry::kHalfTurn;
}

std::string symmetryName(BoardSymmetry symmetry) {
  switch (symmetry) {
    case BoardSymmetry::kNone:
      return "none";
    case BoardSymmetry::kHalfTurn:
      return "half turn";
    case BoardSymmetry::kQuarterTurn:
      return "quarter turn";
  }
  return "?";
}

std::vector<std::size_t> boardsSeenBy(const MatLayout& layout, const std::string& camera) {
  std::vector<std::size_t> boards;
  for (std::size_t b = 0; b < layout.boards.size(); ++b) {
    const auto& seenBy = layout.boards[b].seenBy;
    if (std::find(seenBy.begin(), seenBy.end(), camera) != seenBy.end()) boards.push_back(b);
  }
  return boards;
}

}  // namespace surroundd::processing
