#pragma once
// The printed targets calibration looks for, and where their corners are.
//
// Pattern coordinates are those of the target as printed and seen from the front: u to the right,
// v down, metres. A checkerboard is known by its inner corners (where four squares meet): inner
// corner (i, j) sits at (i, j) * square, listed row by row as OpenCV lists them. Its square (0, 0),
// the outer square touching inner corner (0, 0) diagonally, is black, and one corner count is odd
// and the other even: then a half turn of the board changes which colour comes first, so a
// detector can tell which end is which (see target_detection.hpp). An ArUco marker's pattern
// origin is its top-left corner; its corners are listed clockwise from there, as OpenCV does.
//
// Ground markers lie flat and face up at known places in the vehicle frame (x forward, y left, z
// up, metres). A marker's pattern u axis points along `yawDeg` (0: vehicle +x, 90: +y); its v axis
// is u x up, so that a camera above sees the print unmirrored.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

namespace surroundd::processing {

struct Checkerboard {
  cv::Size innerCorners;  // columns x rows of inner corners, each at least 2
  double squareM = 0;     // side of a square, metres

  // Pattern-frame positions of the inner corners (z = 0), row by row.
  std::vector<cv::Point3f> patternCorners() const;
  // One count odd and the other even: the board's two ends look different.
  bool orientationIsUnambiguous() const {
    return (innerCorners.width + innerCorners.height) % 2 == 1;
  }
};

enum class MarkerKind { kCheckerboard, kAruco };

struct GroundMarker {
  std::string name;  // for messages
  MarkerKind kind = MarkerKind::kCheckerboard;
  Checkerboard board;     // kCheckerboard
  int arucoId = 0;        // kAruco: the marker's id in the layout's dictionary
  double arucoSideM = 0;  // kAruco: side of the black square, border included, metres
  cv::Vec3d centre;       // vehicle frame: centre of the inner-corner grid, or of the marker
  double yawDeg = 0;      // direction of the pattern's u axis on the ground

  cv::Vec3d uAxis() const;
  cv::Vec3d vAxis() const;
  // Vehicle-frame position of the pattern origin (inner corner (0, 0); the marker's top left).
  cv::Vec3d origin() const;
  cv::Vec3d toVehicle(cv::Point2d pattern) const {
    return origin() + pattern.x * uAxis() + pattern.y * vAxis();
  }
  // Vehicle-frame corners in the order a detector reports them.
  std::vector<cv::Point3d> corners() const;
};

struct MarkerLayout {
  int arucoDictionary = 0;  // cv::aruco::PREDEFINED_DICTIONARY_NAME; see arucoDictionaryByName()
  std::vector<GroundMarker> markers;
};

// OpenCV's predefined ArUco dictionaries by their short names ("4x4_50", "6x6_250",
// "apriltag_36h11", ...); nullopt for an unknown name.
std::optional<int> arucoDictionaryByName(std::string_view name);
// The names arucoDictionaryByName() knows, comma-separated, for messages.
std::string arucoDictionaryNames();
// The short name of a dictionary arucoDictionaryByName() knows; "?" for another.
std::string_view arucoDictionaryName(int dictionary);

}  // namespace surroundd::processing
