#pragma once
// Pictures of reprojection residuals: each point as a dot where it was detected, with its residual
// (reprojected - detected) drawn as a line magnified enough to see, and a legend that says by how
// much. Systematic errors show as fields of lines pointing one way (a wrong distortion, a board
// that is not flat); random ones as short lines in all directions.

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace surroundd::calibrate {

struct ResidualSet {
  std::vector<cv::Point2d> detected;
  std::vector<cv::Point2d> residuals;  // pixels
  cv::Scalar colour;                   // BGR
};

// Draws the sets onto `background` (8-bit BGR, the camera's image size; a small one is enlarged
// with the points) and writes a PNG. `title` is the legend's first line. `magnification`: how many
// times longer than the residual a line is drawn, fixed so that pictures of two runs compare
// (the legend draws a 1 px residual to scale); default: chosen from the residuals.
void writeResidualPlot(const std::filesystem::path& file, const cv::Mat& background,
                       std::span<const ResidualSet> sets, const std::string& title,
                       std::optional<double> magnification = std::nullopt);

// White text with a dark outline, legible on any picture (0.6 Hershey simplex, 24 px a line).
void drawLabel(cv::Mat& canvas, const std::string& text, cv::Point at);

// Distinct colours for up to a few dozen sets (per image, per marker).
cv::Scalar setColour(std::size_t index);

}  // namespace surroundd::calibrate
