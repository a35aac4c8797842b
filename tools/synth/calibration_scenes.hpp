#pragma once
// Where the synthetic calibration targets go: checkerboard poses that cover a camera's field (for
// intrinsics), and ground markers laid out where a rig camera looks (for extrinsics). Both are
// pure functions of their inputs and the seed, and every target they return is seen whole, from
// its printed side, large enough to be found (see TargetRenderer for the pictures).

#include <cstdint>
#include <vector>

#include "processing/calibration/calibration_targets.hpp"
#include "processing/rig.hpp"

namespace surroundd::synth {

// `count` board poses in the camera frame (X_camera = rotation * X_pattern + position), spread
// over the image on a grid of cells, tilted 15..45 degrees in varying directions. Every corner of
// the print stays inside the image and less than 80 degrees off the optical axis (OpenCV's fisheye
// calibration cannot take points at or past 90 degrees). Throws std::runtime_error when a cell
// cannot hold the board.
std::vector<processing::Pose> boardPosesCoveringField(const processing::Intrinsics& intrinsics,
                                                      const processing::Checkerboard& board,
                                                      int count, std::uint64_t seed);

struct GroundMarkerRequest {
  int boards = 4;
  processing::Checkerboard board{{5, 4}, 0.15};
  int arucoMarkers = 4;
  double arucoSideM = 0.3;
  int arucoDictionary = 0;  // cv::aruco::DICT_4X4_50
  int firstArucoId = 0;     // ids firstArucoId, firstArucoId + 1, ...
  // Markers seen at a grazing angle are squashed beyond what a detector finds: the line of sight
  // to a marker's centre rises at least this much above the ground.
  double minElevationDeg = 20;
  std::uint64_t seed = 1;
};

// What a marker must look like in a picture for its detector. The defaults are the raw-picture
// detectors' (target_detection.hpp): squares of 9 px, modules of 4 px, and no strong shear, on
// which cornerSubPix drifts (1.6 px on the acute corners of a far ArUco marker).
struct ViewFit {
  double minBoardSquarePx = 9;
  double minArucoModulePx = 4;
  bool limitShear = true;  // every angle of the outline within 55..125 degrees
};

// Whether `camera` sees the whole print of a ground marker, margin included, as `fit` asks.
bool markerFitsView(const processing::CameraCalibration& camera,
                    const processing::GroundMarker& marker, int arucoDictionary,
                    const ViewFit& fit = {});

// Markers on the ground (z = 0) that `camera` sees whole, apart from each other, roughly facing it;
// as many as the request asks for where they fit (fewer when the view has no room).
processing::MarkerLayout groundMarkersInView(const processing::CameraCalibration& camera,
                                             const GroundMarkerRequest& request);

}  // namespace surroundd::synth
