#include "tools/calibrate/residual_plot.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace surroundd::calibrate {
namespace {

// Small images are drawn at least this wide, so that dots, lines and text stay legible.
constexpr int kMinimumWidth = 1280;

// A magnification from the 1-2-5 series that makes the 95th-percentile residual about 3 % of the
// picture's width: long enough to see a direction, short enough not to cross the neighbours.
double magnificationFor(std::span<const ResidualSet> sets, double width) {
  std::vector<double> lengths;
  for (const auto& set : sets) {
    for (const auto& r : set.residuals) {
      if (std::isfinite(r.x) && std::isfinite(r.y)) lengths.push_back(std::hypot(r.x, r.y));
    }
  }
  if (lengths.empty()) return 1;
  const auto p95 = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() * 95 / 100);
  std::nth_element(lengths.begin(), p95, lengths.end());
  const double wanted = 0.03 * width / std::max(*p95, 1e-3);
  const double decade = std::pow(10.0, std::floor(std::log10(wanted)));
  for (const double step : {5.0, 2.0, 1.0}) {
    if (step * decade <= wanted) return step * decade;
  }
  return decade;
}

}  // namespace

void drawLabel(cv::Mat& canvas, const std::string& text, cv::Point at) {
  cv::putText(canvas, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
  cv::putText(canvas, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
}

cv::Scalar setColour(std::size_t index) {
  // Hues spaced by the golden angle: neighbours in the list get far-apart colours.
  const double hue = std::fmod(static_cast<double>(index) * 137.508, 360.0) / 2;  // OpenCV: 0..180
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue, 200, 255)), bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const auto c = bgr.at<cv::Vec3b>(0, 0);
  return {static_cast<double>(c[0]), static_cast<double>(c[1]), static_cast<double>(c[2])};
}

void writeResidualPlot(const std::filesystem::path& file, const cv::Mat& background,
                       std::span<const ResidualSet> sets, const std::string& title,
                       std::optional<double> fixedMagnification) {
  const double scale = std::max(1.0, static_cast<double>(kMinimumWidth) / background.cols);
  cv::Mat canvas;
  cv::resize(background, canvas, {}, scale, scale, cv::INTER_LINEAR);
  const double magnification =
      fixedMagnification ? *fixedMagnification : magnificationFor(sets, canvas.cols) / scale;
  for (const auto& set : sets) {
    for (std::size_t i = 0; i < set.detected.size(); ++i) {
      const cv::Point2d at = set.detected[i] * scale;
      const cv::Point2d r = set.residuals[i];
      if (std::isfinite(r.x) && std::isfinite(r.y)) {
        cv::line(canvas, at, at + r * magnification * scale, set.colour, 1, cv::LINE_AA);
      }
      cv::circle(canvas, at, 2, set.colour, cv::FILLED, cv::LINE_AA);
    }
  }
  const std::string legend =
      fmt::format("residuals x{:g}; this bar is a 1 px residual:", magnification);
  int y = 24;
  for (const auto& line : {title, legend}) {
    drawLabel(canvas, line, {12, y});
    y += 24;
  }
  // The scale bar, after the legend's last line, as long as a 1 px residual is drawn.
  const int barStart =
      12 + cv::getTextSize(legend, cv::FONT_HERSHEY_SIMPLEX, 0.6, 1, nullptr).width + 8;
  const int barLength = static_cast<int>(std::lround(magnification * scale));
  cv::line(canvas, {barStart, y - 30}, {barStart + barLength, y - 30}, cv::Scalar(0, 0, 0), 4);
  cv::line(canvas, {barStart, y - 30}, {barStart + barLength, y - 30}, cv::Scalar(255, 255, 255),
           2);
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  if (!cv::imwrite(file.string(), canvas)) {
    throw std::runtime_error(fmt::format("{}: cannot write the image", file.string()));
  }
}

}  // namespace surroundd::calibrate
