#include "tools/calibrate/mask/mask_overlay.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace surroundd::calibrate {
namespace {

// White text on black, sized to the picture (legible from a 320-pixel test picture to a 4K one),
// in the corner where it hides the least of the mask.
void drawLabel(cv::Mat& picture, const cv::Mat& mask, const std::vector<std::string>& lines) {
  const cv::Scalar background(0, 0, 0);
  const cv::Scalar text(255, 255, 255);
  constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
  const double scale = std::clamp(picture.cols / 1280.0, 0.35, 2.0);
  const int thickness = scale < 1 ? 1 : 2;
  const int pad = static_cast<int>(std::lround(6 * scale)) + 2;
  int width = 0, textHeight = 0, descent = 0;
  for (const auto& line : lines) {
    int baseline = 0;
    const cv::Size size = cv::getTextSize(line, kFont, scale, thickness, &baseline);
    width = std::max(width, size.width);
    textHeight = std::max(textHeight, size.height);
    descent = std::max(descent, baseline);
  }
  const int lineHeight = textHeight + descent + pad;
  const int count = static_cast<int>(lines.size());
  const cv::Size box(std::min(width + 2 * pad, picture.cols),
                     std::min(lineHeight * count + pad, picture.rows));
  const int right = picture.cols - box.width, bottom = picture.rows - box.height;
  cv::Rect best;
  int bestHidden = -1;
  for (const cv::Point corner :
       {cv::Point(0, 0), cv::Point(right, 0), cv::Point(0, bottom), cv::Point(right, bottom)}) {
    const cv::Rect rect(corner, box);
    const int hidden = cv::countNonZero(mask(rect));
    if (bestHidden < 0 || hidden < bestHidden) {
      best = rect;
      bestHidden = hidden;
    }
  }
  cv::rectangle(picture, best, background, cv::FILLED);
  for (int i = 0; i < count; ++i) {
    cv::putText(picture, lines[static_cast<std::size_t>(i)],
                best.tl() + cv::Point(pad, pad + lineHeight * i + textHeight), kFont, scale, text,
                thickness, cv::LINE_AA);
  }
}

}  // namespace

cv::Mat maskOverlay(const cv::Mat& picture, const cv::Mat& mask,
                    const std::vector<std::string>& label) {
  // BGR. Yellow outlines stand out on the red tint and on most road scenes.
  const cv::Scalar tint(0, 0, 255);
  const cv::Scalar outline(0, 255, 255);
  cv::Mat out = picture.clone();
  cv::Mat tinted;
  cv::addWeighted(picture, 0.5, cv::Mat(picture.size(), picture.type(), tint), 0.5, 0, tinted);
  tinted.copyTo(out, mask);
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_LIST, cv::CHAIN_APPROX_SIMPLE);
  cv::drawContours(out, contours, -1, outline, 2);
  drawLabel(out, mask, label);
  return out;
}

}  // namespace surroundd::calibrate
