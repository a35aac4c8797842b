#include "tools/calibrate/intrinsics/intrinsics_report.hpp"

#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "tools/calibrate/calibration_output.hpp"
#include "tools/calibrate/residual_plot.hpp"

namespace surroundd::calibrate {
namespace {

constexpr double kToDeg = 180 / std::numbers::pi;
constexpr int kMinimumWidth = 1280;  // as the residual picture: legible dots and text

}  // namespace

void printViewTable(const processing::IntrinsicCalibration& result, std::optional<double> squareMm,
                    const processing::CalibrationLimits& limits, std::ostream& log) {
  log << fmt::format("  {:<28} {:>7} {:>9} {:>8} {:>10}\n", "view", "corners", "RMS px", "tilt deg",
                     squareMm ? "distance m" : "dist. sq.");
  for (const auto& view : result.views) {
    // The board's normal against the line of sight to it: 0 when it faces the camera.
    const cv::Vec3d normal(view.boardInCamera.rotation(0, 2), view.boardInCamera.rotation(1, 2),
                           view.boardInCamera.rotation(2, 2));
    const cv::Vec3d& position = view.boardInCamera.position;
    const double tilt =
        std::acos(std::min(1.0, std::abs(normal.dot(position)) / cv::norm(position))) * kToDeg;
    const double distance = cv::norm(position) * (squareMm ? *squareMm / 1000 : 1);
    log << fmt::format(
        "  {:<28} {:>7} {:>9.3f} {:>8.1f} {:>10.3g}{}\n", view.name, view.corners.size(),
        view.rmsPx, tilt, distance,
        view.rmsPx > limits.viewRmsLimitPx(view.edgeWidthPx) ? "  <- above the limit" : "");
  }
}

void printLens(const processing::IntrinsicCalibration& result, const processing::FieldOfView& field,
               std::ostream& log) {
  const auto& in = result.intrinsics;
  const auto& u = result.uncertainty;
  const bool fisheye = in.model == processing::LensModel::kFisheye;
  std::size_t corners = 0;
  for (const auto& view : result.views) corners += view.corners.size();
  log << fmt::format("RMS {:.3f} px over {} corners in {} views\n", result.rmsPx, corners,
                     result.views.size());
  log << fmt::format("{} (+- one standard deviation):\n", processing::lensModelName(in.model));
  log << fmt::format(
      "  fx {:.3f} +- {:.3f}  fy {:.3f} +- {:.3f}  cx {:.3f} +- {:.3f}  cy {:.3f} "
      "+- {:.3f} px\n",
      in.fx, u.fx, in.fy, u.fy, in.cx, u.cx, in.cy, u.cy);
  static constexpr std::array<const char*, 5> kPinholeNames{"k1", "k2", "p1", "p2", "k3"};
  static constexpr std::array<const char*, 5> kFisheyeNames{"k1", "k2", "k3", "k4", ""};
  log << " ";
  for (std::size_t i = 0; i < (fisheye ? 4u : 5u); ++i) {
    log << fmt::format(" {} {:.6g} +- {:.2g}", (fisheye ? kFisheyeNames : kPinholeNames)[i],
                       in.distortion[i], u.distortion[i]);
  }
  log << "\n";
  log << fmt::format("field of view {:.1f} deg{}; the corners reached {:.1f} deg off the axis\n",
                     field.fullDeg,
                     field.fromImageCircle ? " (to the edge of the image circle)" : "",
                     result.widestCornerAngleRad * kToDeg);
  if (!field.note.empty()) log << "  note: " << field.note << "\n";
}

void printVerdict(const processing::Verdict& verdict, std::ostream& log) {
  log << (verdict.passed ? "verdict: PASS\n" : "verdict: FAIL\n");
  for (const auto& failure : verdict.failures) log << "  - " << failure << "\n";
  if (!verdict.passed && !verdict.viewsToDrop.empty()) {
    log << fmt::format("  views to drop first (--exclude {})\n",
                       fmt::join(verdict.viewsToDrop, ","));
  }
}

void writeCoveragePlot(const std::filesystem::path& file, const processing::CoverageMap& coverage,
                       const processing::ImageCircle& circle,
                       std::span<const processing::BoardView> views) {
  const cv::Size size = coverage.imageSize;
  cv::Mat canvas(size, CV_8UC3, cv::Scalar(0, 0, 0));
  canvas.setTo(cv::Scalar(40, 40, 40), circle.lit);
  cv::Mat cells = canvas.clone();
  for (int row = 0; row < coverage.cells.height; ++row) {
    for (int column = 0; column < coverage.cells.width; ++column) {
      if (coverage.inLens.at<std::uint8_t>(row, column) == 0) continue;
      const bool covered = coverage.cornerCounts.at<int>(row, column) > 0;
      cv::rectangle(cells, coverage.cellRect(column, row),
                    covered ? cv::Scalar(60, 160, 60) : cv::Scalar(50, 50, 190), cv::FILLED);
    }
  }
  cv::addWeighted(canvas, 0.5, cells, 0.5, 0, canvas);
  const double scale = std::max(1.0, static_cast<double>(kMinimumWidth) / size.width);
  cv::resize(canvas, canvas, {}, scale, scale, cv::INTER_NEAREST);
  for (int row = 0; row <= coverage.cells.height; ++row) {
    // On the cells' own (whole-pixel) edges, scaled.
    const int y = static_cast<int>(coverage.cellRect(0, row).y * scale);
    cv::line(canvas, {0, y}, {canvas.cols, y}, cv::Scalar(90, 90, 90), 1);
  }
  for (int column = 0; column <= coverage.cells.width; ++column) {
    const int x = static_cast<int>(coverage.cellRect(column, 0).x * scale);
    cv::line(canvas, {x, 0}, {x, canvas.rows}, cv::Scalar(90, 90, 90), 1);
  }
  for (std::size_t v = 0; v < views.size(); ++v) {
    for (const auto& corner : views[v].corners) {
      cv::circle(canvas, cv::Point2d(corner) * scale, 2, setColour(v), cv::FILLED, cv::LINE_AA);
    }
  }
  drawLabel(canvas,
            fmt::format("{} views: corners cover {:.0f} % of the lens's cells", views.size(),
                        100 * coverage.coveredShare),
            {12, 24});
  drawLabel(canvas, "green: cell with corners; red: empty cell in the lens; dark: outside it",
            {12, 48});
  writePng(file, canvas);
}

}  // namespace surroundd::calibrate
