#pragma once
// OCamCalib's calib_results.txt (Scaramuzza's toolbox, export_data): the lens of one camera.
//
// The file is in OCamCalib's own axes: its centre (xc, yc) is (ROW, COLUMN), its first image axis
// runs down the rows, and its affine matrix [c d; e 1] maps (row, column) offsets. The project's
// lens.model ocam (processing/lens/ocam_lens.hpp) is written in image order instead, as the pjlab
// files are: cx, cy = (column, row), u = c a + d b + cx, v = e a + b + cy for the projected point
// (a, b) along (column, row). Swapping the axes gives u = a' + e b', v = d a' + c b'; dividing
// through by c restores the 1 in the corner, so the polynomials are rescaled by c (exactly).

#include <filesystem>

#include "processing/lens/camera_model.hpp"

namespace surroundd::calibrate {

// Throws UsageError naming the file, line and section for anything that is not that layout.
processing::Intrinsics readOcamResults(const std::filesystem::path& file);

// The inverse of readOcamResults' conversion: OCamCalib's own (c, d, e, xc = row, yc = column, pol,
// invpol) for a lens in the project's terms. For tests and for writing the file back.
struct OcamNative {
  double c = 1, d = 0, e = 0, xcRow = 0, ycColumn = 0;
  std::vector<double> pol, invpol;
  cv::Size imageSize;
};
OcamNative toOcamNative(const processing::Intrinsics& lens);
processing::Intrinsics fromOcamNative(const OcamNative& native);

}  // namespace surroundd::calibrate
