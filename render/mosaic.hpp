#pragma once
// The debug view: every camera's frame in a labelled grid (2x2 for four cameras, in rig order),
// each scaled to fit its tile with its aspect ratio kept. A camera without a frame shows a grey
// tile that says so.

#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace surroundd::render {

class Mosaic {
 public:
  Mosaic(cv::Size outputSize, std::vector<std::string> labels);

  // `frames[i]` is camera i's 8-bit BGR image, or nullptr when it has none; `faults[i]`, when
  // given and not null, says what is wrong with camera i (its tile is dimmed and says so). `out`
  // must be 8-bit BGR of outputSize(); it is drawn over completely.
  void compose(std::span<const cv::Mat* const> frames, cv::Mat& out,
               std::span<const char* const> faults = {}) const;

  cv::Size outputSize() const { return outputSize_; }
  // Tile of camera i in the output image.
  cv::Rect tile(std::size_t camera) const { return tiles_.at(camera); }

 private:
  void drawLabel(cv::Mat& tile, const std::string& text) const;

  cv::Size outputSize_;
  std::vector<std::string> labels_;
  std::vector<cv::Rect> tiles_;
};

}  // namespace surroundd::render
