#pragma once
// Finds a calibration mat's boards in one camera's picture, fisheye or pinhole.
//
// A large board near the car is seen at a slant and, on a fisheye, bent, which defeats OpenCV's
// detectors on the raw picture. So each board the camera must see is looked for in a top view of
// the ground around the place the layout gives it, resampled from the picture through the lens
// model and the camera's nominal pose: there it looks like a flat, nearly upright print. The
// corners found there are mapped back through the same nominal pose and lens (the top view is
// only a change of sampling, so a nominal pose that is off moves nothing but the search window).
// The corners are refined in the top view, not again in the picture: on the generated fisheye
// mats, cornerSubPix on the slanted, compressed squares of the picture doubled the reprojection
// RMS (0.16 against 0.51 px on the worst camera) and the seam error.
//
// Which corner is which: the colours fix it for a board whose corner counts differ in parity. For
// a symmetric board (ground_mat.hpp) the orientations the colours allow are all candidates, and
// the rule is: the one whose corners the nominal pose puts nearest the layout's corners wins. That
// is right while the nominal mount puts the board within a quarter turn (half-turn symmetric
// boards) or an eighth of a turn (quarter-turn symmetric ones) of its layout yaw, which a mount
// measured by hand does by far. A board found turned by more than an eighth of a turn from its
// layout yaw is refused: the layout's yaw_deg or the nominal mount is wrong.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/ground_mat.hpp"
#include "processing/rig.hpp"

namespace surroundd::processing {

struct MatBoardSighting {
  std::size_t board = 0;               // index into MatLayout::boards
  std::vector<cv::Point2f> pixels;     // in GroundMarker::corners() order
  bool orientedByNominalPose = false;  // symmetric board: the nominal pose chose the orientation
};

struct MatBoardMiss {
  std::size_t board = 0;
  std::string reason;  // e.g. "not found within 0.6 m of its place in the layout"
};

struct MatBoardDetection {
  std::vector<MatBoardSighting> found;
  std::vector<MatBoardMiss> missed;
};

struct MatDetectionSettings {
  // How far the nominal pose may put a board from where the picture shows it: the top view
  // reaches this far beyond the board's print.
  double searchMarginM = 0.6;
  double topViewPxPerSquare = 32;  // resampling of the top view (24: twice the position error)
  int topViewMaxSidePx = 1400;     // bounds the detector's time on very large boards
};

// Looks for every board of `layout` that names `nominal.name` in its seenBy. `gray`: CV_8U, the
// size of the camera's lens. `nominal`: the camera's lens and its assumed mount (T_vehicle_camera).
MatBoardDetection findMatBoards(const cv::Mat& gray, const MatLayout& layout,
                                const CameraCalibration& nominal,
                                const MatDetectionSettings& settings = {});

}  // namespace surroundd::processing
