#pragma once
// The vehicle's own body in a camera's pictures, found from a drive: the body moves with the
// camera, so where the camera looks down at the road, a pixel that keeps its content from one
// picture to the next while the ground under the others slides past is body (a bumper, a mirror's
// housing, the roof). What a measured box or polygon cannot say — the grille the front camera
// looks through, a mirror that sticks out, a bumper below a camera that sits inside the body's box
// — the pictures do.
//
// Per pixel it counts the pairs of pictures `span` apart in which its content changed by more
// than a few levels (the pictures blurred against sensor noise and compression, and brought to one
// brightness against the camera's auto exposure); a pixel that changed in more than a quarter of
// them moved. The scene is then flooded in from the rays above the horizon (the sky, far walls)
// through what moved, stopped by what did not and by static edges — an edge of one orientation,
// in the same place in most pictures: the body's outline, which stays put even where the body
// mirrors the moving sky (a glossy roof) or a window shows the street. What the flood leaves below
// the horizon, in regions that reach the picture's or the lens's edge (a camera sees its own car
// from the edge in), is body; ground with no texture that the scene surrounds is not.
//
// Where paint mirrors the road at a grazing angle (a flank seen from a mirror's camera) the body's
// picture moves with the road and is not found: a mask found this way is added to the one computed
// from the vehicle's measures, not put in its place.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/rig.hpp"

namespace surroundd::processing {

struct BodyFromMotionSettings {
  // A change of more than this many grey levels (after the blur and the brightness match) is a
  // change; the pictures' noise after the blur stays well under it.
  double changeLevels = 6;
  // Each picture is compared with the one this many before it: far enough for the ground to move
  // well past its texture's scale, near enough for the light to stay.
  int span = 4;
  // A pixel that changed in at most this share of the pairs is still.
  double stillShare = 0.25;
  // A static edge: a gradient stronger than this (grey levels per pixel, Sobel) in at least
  // `edgePresence` of the pictures, of one orientation (the summed structure tensor's coherence at
  // least `edgeCoherence`). The body's outline is one even where the body mirrors what moves.
  double edgeStrength = 24;
  double edgePresence = 0.6;
  double edgeCoherence = 0.8;
  // Regions of the mask smaller than this share of the picture are dropped.
  double minRegionShare = 0.002;
};

class BodyFromMotion {
 public:
  // For `camera`'s pictures (its lens's size; its mount says which rays point down).
  explicit BodyFromMotion(const CameraCalibration& camera, BodyFromMotionSettings settings = {});

  // The next picture of the drive, 8-bit BGR; consecutive pictures should be far enough apart
  // that the ground moves by a few pixels (a tenth of a second or more at walking pace).
  void add(const cv::Mat& picture);
  // Pairs of pictures compared so far.
  int pairs() const { return pairs_; }
  // The share of the candidate pixels (rays that point down) that moved: near 0 when the vehicle
  // stood still, and the mask then means nothing.
  double movingShare() const;
  // 255 where the camera sees its vehicle's body, 0 elsewhere (CV_8U, the lens's size).
  cv::Mat mask() const;
  // 255 where an edge stayed where it was, of the same orientation, in most pictures.
  cv::Mat staticEdges() const;

 private:
  BodyFromMotionSettings settings_;
  cv::Mat candidates_;           // CV_8U: 255 where the ray points down, inside the lens's field
  cv::Mat sky_;                  // and where it points up
  cv::Mat edge_;                 // the picture's border and the lens's field's edge
  std::vector<cv::Mat> recent_;  // CV_32F: the last `span` pictures, blurred grey, oldest first
  cv::Mat grey_, blurred_, change_;
  cv::Mat changed_;       // CV_16U: per pixel, the pairs in which it changed
  cv::Mat edged_;         // CV_16U: per pixel, the pictures with an edge there
  cv::Mat xx_, yy_, xy_;  // CV_32F: the structure tensor summed over the pictures
  cv::Mat gx_, gy_;
  int pairs_ = 0;
  int pictures_ = 0;
};

// The mask's outlines as polygons (the outer edge of each region, holes ignored), simplified to
// within `tolerancePx`: for a rig's `body_mask: {polygons: ...}`.
std::vector<std::vector<cv::Point>> maskOutlines(const cv::Mat& mask, double tolerancePx);

}  // namespace surroundd::processing
