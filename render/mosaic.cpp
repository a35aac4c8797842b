#include "render/mosaic.hpp"

#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace surroundd::render {
namespace {

// Largest rectangle with the frame's aspect ratio centred inside `tile`.
cv::Rect fitInside(cv::Size frame, const cv::Rect& tile) {
  const double scale = std::min(static_cast<double>(tile.width) / frame.width,
                                static_cast<double>(tile.height) / frame.height);
  const int width = std::max(1, static_cast<int>(std::lround(frame.width * scale)));
  const int height = std::max(1, static_cast<int>(std::lround(frame.height * scale)));
  return {tile.x + (tile.width - width) / 2, tile.y + (tile.height - height) / 2, width, height};
}

}  // namespace

Mosaic::Mosaic(cv::Size outputSize, std::vector<std::string> labels)
    : outputSize_(outputSize), labels_(std::move(labels)) {
  if (labels_.empty()) throw std::invalid_argument("Mosaic: no cameras");
  const int count = static_cast<int>(labels_.size());
  const int columns = static_cast<int>(std::ceil(std::sqrt(count)));
  const int rows = (count + columns - 1) / columns;
  for (int i = 0; i < count; ++i) {
    const int column = i % columns;
    const int row = i / columns;
    const int x0 = outputSize.width * column / columns;
    const int y0 = outputSize.height * row / rows;
    const int x1 = outputSize.width * (column + 1) / columns;
    const int y1 = outputSize.height * (row + 1) / rows;
    tiles_.emplace_back(x0, y0, x1 - x0, y1 - y0);
  }
}

void Mosaic::compose(std::span<const cv::Mat* const> frames, cv::Mat& out,
                     std::span<const char* const> faults) const {
  const cv::Scalar background(0, 0, 0);
  const cv::Scalar missing(96, 96, 96);
  CV_Assert(out.type() == CV_8UC3 && out.size() == outputSize_ && frames.size() == tiles_.size());
  for (std::size_t i = 0; i < tiles_.size(); ++i) {
    cv::Mat tile = out(tiles_[i]);
    const cv::Mat* frame = frames[i];
    if (frame == nullptr || frame->empty()) {
      tile.setTo(missing);
      drawLabel(tile, labels_[i] + ": no frame");
      continue;
    }
    const cv::Rect fit = fitInside(frame->size(), tiles_[i]);
    if (fit.size() != tiles_[i].size()) tile.setTo(background);
    // Writes into the view of `out` in place: the destination already has the requested size.
    cv::Mat target = out(fit);
    cv::resize(*frame, target, fit.size(), 0, 0, cv::INTER_AREA);
    const char* fault = i < faults.size() ? faults[i] : nullptr;
    if (fault != nullptr) {
      target.convertTo(target, -1, 0.4, 40);  // dimmed, in place
      drawLabel(tile, labels_[i] + ": " + fault);
    } else {
      drawLabel(tile, labels_[i]);
    }
  }
}

void Mosaic::drawLabel(cv::Mat& tile, const std::string& text) const {
  const cv::Scalar textColour(255, 255, 255);
  const cv::Scalar shadow(0, 0, 0);
  const double scale = std::max(0.4, tile.rows / 400.0);
  const int thickness = std::max(1, static_cast<int>(std::lround(scale * 1.5)));
  const cv::Point origin(static_cast<int>(8 * scale), static_cast<int>(28 * scale));
  cv::putText(tile, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, shadow, thickness + 2,
              cv::LINE_AA);
  cv::putText(tile, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, textColour, thickness,
              cv::LINE_AA);
}

}  // namespace surroundd::render
