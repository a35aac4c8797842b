#pragma once
// The ground as seen from above through calibrated cameras: which picture pixel shows each point
// of a top-view grid (front up, the vehicle's left to the left), and the cameras' pictures
// resampled onto it and stitched. Shared by the seam measures (tools/bench) and the guided mat
// calibration's stitched view (tools/calibrate).

#include <span>

#include <opencv2/core.hpp>

#include "processing/rig.hpp"

namespace surroundd::processing {

// A square-pixel grid on the ground plane z = 0, vehicle frame: row r, column c shows
// (centre.x + (size.height / 2 - r) * metresPerPx, centre.y + (size.width / 2 - c) * metresPerPx).
struct GroundGrid {
  cv::Point2d centre;  // metres
  double metresPerPx = 0.01;
  cv::Size size{160, 160};

  cv::Vec3d groundAt(int row, int column) const {
    return {centre.x + (size.height / 2.0 - row) * metresPerPx,
            centre.y + (size.width / 2.0 - column) * metresPerPx, 0};
  }
  // The grid position (column, row) of a ground point: groundAt's inverse.
  cv::Point2d pixelOf(const cv::Vec3d& ground) const {
    return {size.width / 2.0 - (ground[1] - centre.y) / metresPerPx,
            size.height / 2.0 - (ground[0] - centre.x) / metresPerPx};
  }
};

struct GroundSampling {
  cv::Mat mapX, mapY;  // CV_32F, for cv::remap; -1 where the camera does not see that ground
  int seen = 0;        // grid points the camera sees
};

// Where `camera` (lens and mount) sees each grid point: in its picture, in front of it, and not
// behind its body mask.
GroundSampling groundSampling(const CameraCalibration& camera, const GroundGrid& grid);

// The pictures (8-bit BGR, one per camera, each its lens's size) resampled onto `grid` and
// averaged where cameras overlap, so a mount that is off shows as a doubled ground; black where
// no camera sees.
cv::Mat stitchedTopView(std::span<const CameraCalibration> cameras, std::span<const cv::Mat> bgr,
                        const GroundGrid& grid);

}  // namespace surroundd::processing
