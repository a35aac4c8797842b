#pragma once
// Finds a layout's ground markers in one camera image and pairs their corners with the markers'
// vehicle-frame positions, ready for calibrateExtrinsics().
//
// ArUco markers name themselves by id. Checkerboards of one pattern look alike, so each found
// board is matched to the layout's board of that pattern whose centre the prior pose (the rig's
// nominal mount) puts nearest in the image; a layout whose boards all differ in pattern needs no
// prior at all.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/calibration_targets.hpp"
#include "processing/calibration/extrinsic_calibration.hpp"
#include "processing/lens/camera_model.hpp"
#include "processing/rig.hpp"

namespace surroundd::processing {

struct MarkerSighting {
  std::size_t marker = 0;           // index into the layout
  std::vector<cv::Point2f> pixels;  // in GroundMarker::corners() order
};

// `gray`: CV_8U. `prior`: the camera's assumed pose (T_vehicle_camera).
std::vector<MarkerSighting> findGroundMarkers(const cv::Mat& gray, const MarkerLayout& layout,
                                              const CameraModel& model, const Pose& prior);

// Corner correspondences of the sightings, labelled "<marker name> corner <k>".
std::vector<PointCorrespondence> correspondencesOf(const MarkerLayout& layout,
                                                   const std::vector<MarkerSighting>& sightings);

}  // namespace surroundd::processing
