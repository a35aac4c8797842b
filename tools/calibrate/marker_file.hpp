#pragma once
// The YAML files that say where calibration points are on the vehicle.
//
// Ground markers (--markers), vehicle frame (x forward, y left, z up, metres):
//
//   aruco_dictionary: 4x4_50         # for aruco markers; default 4x4_50
//   markers:
//     - name: front_left             # required, unique
//       type: checkerboard           # checkerboard | aruco
//       inner_corners: [5, 4]        # checkerboard: columns, rows (one odd, one even)
//       square_m: 0.15               # checkerboard: side of a square
//       x_m: 3.1                     # centre: of the inner-corner grid, or of the marker
//       y_m: 1.2
//       z_m: 0                       # default 0: on the ground
//       yaw_deg: 90                  # direction of the print's first row (u axis); default 0
//     - {name: tag7, type: aruco, id: 7, side_m: 0.3, x_m: 2.5, y_m: -1.0, yaw_deg: 0}
//
// The print lies face up; its geometry is processing/calibration/calibration_targets.hpp's.
//
// A calibration mat (--mat): checkerboards on the ground, each seen whole by the cameras named
// (one, or two neighbours for the seam between them); the board's two ends may look alike (see
// processing/calibration/ground_mat.hpp). Same frame and placement keys as the markers:
//
//   boards:
//     - name: front_left             # required, unique
//       inner_corners: [7, 6]        # columns, rows of inner corners
//       square_m: 0.2                # side of a square
//       x_m: 3.4                     # centre of the inner-corner grid
//       y_m: 1.9
//       yaw_deg: 0                   # direction of the print's first row; default 0
//       seen_by: [front, left]       # the cameras that must find it
//
// Points with known pixels (--points), for one camera's image:
//
//   points:
//     - {name: pole_base, x_m: 4.0, y_m: 0.5, z_m: 0, u_px: 612.4, v_px: 388.1}

#include <filesystem>
#include <vector>

#include "processing/calibration/calibration_targets.hpp"
#include "processing/calibration/extrinsic_calibration.hpp"
#include "processing/calibration/ground_mat.hpp"

namespace surroundd::calibrate {

// Both throw daemon::ConfigError with every problem, each as file:line:column: key: message.
processing::MarkerLayout loadMarkerFile(const std::filesystem::path& file);
processing::MatLayout loadMatFile(const std::filesystem::path& file);
std::vector<processing::PointCorrespondence> loadPointFile(const std::filesystem::path& file);

}  // namespace surroundd::calibrate
