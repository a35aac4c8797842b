#pragma once
// Where the corners of a calibration fell in the image, and how much of the lens the pictures
// show: the coverage map (what a guided flow fills in, what a verdict asks enough of), the lens's
// image circle found from the pictures, and the field of view that follows from it.

#include <optional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/calibration_board.hpp"
#include "processing/rig.hpp"

namespace surroundd::processing {

// Pixels inside the lens's image circle, found from the brightest value each pixel took over the
// pictures: outside the circle a sensor sees only its dark level, whatever the scene.
struct ImageCircle {
  cv::Mat lit;               // CV_8U, image size, nonzero inside the circle
  bool seenInImage = false;  // the circle ends inside the picture (its four corners are dark)
};

// `brightest`: CV_8U, per pixel the brightest value over the pictures. Dark is judged against
// the pictures' own levels (their darkest and median), not a fixed level: a camera's black is
// 0 on one sensor and 30 on another.
ImageCircle findImageCircle(const cv::Mat& brightest);

// The image cut into cells (`columns` across, square cells); a cell inside the image circle is
// covered when a corner of some view fell in it.
struct CoverageMap {
  cv::Size cells;  // columns x rows
  cv::Size imageSize;
  cv::Mat cornerCounts;     // CV_32S, cells
  cv::Mat inLens;           // CV_8U, cells: the cell's centre is inside the image circle
  double coveredShare = 0;  // covered cells over cells in the lens, 0..1

  cv::Rect cellRect(int column, int row) const;
  // The parts of the image with no corners yet, in words ("the top left corner, the right edge"),
  // for a user moving the board; empty when every part has some.
  std::vector<std::string> uncoveredParts() const;
};

CoverageMap coverageOf(std::span<const BoardView> views, cv::Size imageSize, const cv::Mat& lit,
                       int columns = 8);

struct FieldOfView {
  double fullDeg = 0;            // the whole field, degrees (twice the widest off-axis angle)
  bool fromImageCircle = false;  // the circle is seen: the lens ends there
  std::string note;              // why the value is what it is, when it was limited
};

// How far past the widest angle the board's corners reached a field is taken: a few degrees of
// the polynomial's extrapolation, where it stays close to the lens.
inline constexpr double kFieldPastCornersDeg = 5;

// The widest angle off the optical axis that any of `views`' corners reached through `lens`.
double widestCornerAngleRad(const Intrinsics& lens, std::span<const BoardView> views);

// The field the calibrated lens covers: to the edge of its image circle where the pictures show
// it; to the image corners where they are lit, but never past 180 degrees that way (a lens whose
// circle fills the sensor shows nothing that proves more) nor past where the solved polynomial
// stops increasing; and, given the widest angle the corners reached, never more than
// kFieldPastCornersDeg past it (the polynomial is known only where corners were: extrapolated to
// 193-200 degrees from corners at 72, it put real rigs' far ground in the wrong place).
FieldOfView fieldOfViewOf(const Intrinsics& lens, const ImageCircle& circle,
                          std::optional<double> widestCornerRad = std::nullopt);

}  // namespace surroundd::processing
