#pragma once
// What `surround-calibrate intrinsics` prints and draws: the per-view table (corners, RMS, pose),
// the parameters with their standard deviations, the verdict, and the coverage and residual
// pictures.

#include <filesystem>
#include <optional>
#include <ostream>
#include <span>
#include <string>

#include "processing/calibration/calibration_board.hpp"
#include "processing/calibration/calibration_coverage.hpp"
#include "processing/calibration/calibration_verdict.hpp"
#include "processing/calibration/intrinsic_calibration.hpp"

namespace surroundd::calibrate {

// One row per view: its corners, RMS and the board's pose (tilt from facing the camera, distance
// in squares, or metres when `squareMm` is given); views above their limit are marked.
void printViewTable(const processing::IntrinsicCalibration& result, std::optional<double> squareMm,
                    const processing::CalibrationLimits& limits, std::ostream& log);

// The lens, each parameter +- one standard deviation, and the field of view.
void printLens(const processing::IntrinsicCalibration& result, const processing::FieldOfView& field,
               std::ostream& log);

void printVerdict(const processing::Verdict& verdict, std::ostream& log);

// The lens's image (its circle lit faintly) cut into the coverage map's cells: green with a
// corner, red without one, inside the lens; every corner as a dot in its view's colour; a legend.
void writeCoveragePlot(const std::filesystem::path& file, const processing::CoverageMap& coverage,
                       const processing::ImageCircle& circle,
                       std::span<const processing::BoardView> views);

}  // namespace surroundd::calibrate
