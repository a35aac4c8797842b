#pragma once
// Command line of `surround-calibrate intrinsics`: the pictures, the board, the lens model, what to
// write, and the limits a solve must meet before anything is written.

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "processing/calibration/calibration_board.hpp"
#include "processing/calibration/calibration_verdict.hpp"
#include "processing/lens/camera_model.hpp"

namespace surroundd::calibrate {

struct IntrinsicsOptions {
  std::filesystem::path images;        // folder of board images from one camera
  processing::CalibrationBoard board;  // chessboard (inner corners) or ChArUco (squares)
  processing::LensModel model = processing::LensModel::kPinhole;
  std::filesystem::path out;                       // the lens: block
  std::optional<std::filesystem::path> residuals;  // PNG
  std::optional<std::filesystem::path> coverage;   // PNG
  double residualScale = 50;                       // residual lines: pixels drawn per pixel
  std::optional<double> fieldOfViewDeg;            // fisheye only; default: what the images show
  std::optional<double> squareMm;                  // only scales the poses in the report
  std::vector<std::string> exclude;                // image file names left out
  processing::CalibrationLimits limits;
  double detectTimeoutS = 10;                      // per picture
  std::optional<std::filesystem::path> updateRig;  // rig file whose camera gets the new lens
  std::string camera;                              // with updateRig
};

extern const std::string_view kIntrinsicsUsage;

// `arguments` follow the subcommand. Throws UsageError.
IntrinsicsOptions parseIntrinsics(std::span<const std::string_view> arguments);

}  // namespace surroundd::calibrate
