#pragma once
// Generated pictures of any calibration board for the intrinsics tests: chessboards and ChArUco
// boards, seen whole or cut off at the image edge, optionally made harder (blur, noise,
// vignetting).

#include <opencv2/aruco.hpp>
#include <opencv2/imgproc.hpp>

#include "processing/calibration/calibration_board.hpp"
#include "tests/calibration/calibration_test_support.hpp"

namespace surroundd::calibration::testing {

// The lens rendered `margin` pixels larger on every side, so that boards posed to fit that larger
// image come out cut off at the edges of the real one.
inline processing::Intrinsics widened(processing::Intrinsics lens, int margin) {
  lens.imageSize += cv::Size(2 * margin, 2 * margin);
  lens.cx += margin;
  lens.cy += margin;
  return lens;
}

// What makes pictures harder than a sharp, evenly lit render: what a cheap wide lens and a
// small sensor do to them.
struct Hardship {
  double blurSigmaPx = 0;   // Gaussian blur after the sensor (focus, motion), pixels
  double noiseSigma = 1.5;  // sensor noise, 8-bit levels
  double vignetting = -1;   // CameraPhotometrics::vignetting (0.7: half as bright at the edge);
                            // < 0: the sensor's own (0.1 .. 0.4)
};

// Pictures of `board` covering the field of `lens`; with `margin` > 0, many of them cut off.
inline std::vector<cv::Mat> anyBoardViews(const processing::Intrinsics& lens,
                                          const processing::CalibrationBoard& board, int count,
                                          std::uint64_t seed, int margin = 0,
                                          const Hardship& hardship = {}) {
  const auto rendered = widened(lens, margin);
  constexpr double kSquareM = 0.05;
  // ChArUco inner corners sit one square in from the print's origin, a chessboard's at it: the
  // same poses fit both once the ChArUco print is moved back by a square.
  const processing::Checkerboard grid{board.innerCorners(), kSquareM};
  const synth::TargetRenderer renderer(rendered, kSupersampling);
  std::vector<cv::Mat> images;
  int frame = 0;
  for (auto pose : synth::boardPosesCoveringField(rendered, grid, count, seed)) {
    synth::TargetScene scene;
    if (board.kind == processing::BoardKind::kChessboard) {
      scene.targets.push_back(synth::placeBoard(grid, pose));
    } else {
      pose.position -= pose.rotation * cv::Vec3d(kSquareM, kSquareM, 0);
      scene.targets.push_back(
          synth::placePattern(synth::TargetPattern::charuco(board.size, board.arucoDictionary,
                                                            board.markerToSquare, kSquareM),
                              pose));
    }
    auto photometrics = sensor(0);
    photometrics.noiseSigma = hardship.noiseSigma;
    if (hardship.vignetting >= 0) photometrics.vignetting = hardship.vignetting;
    cv::Mat image = renderer.render({}, scene, photometrics, seed, frame++);
    if (hardship.blurSigmaPx > 0) cv::GaussianBlur(image, image, {0, 0}, hardship.blurSigmaPx);
    images.push_back(image(cv::Rect({margin, margin}, lens.imageSize)).clone());
  }
  return images;
}

inline processing::CalibrationBoard chessboard(int columns, int rows) {
  return {processing::BoardKind::kChessboard, {columns, rows}};
}

inline processing::CalibrationBoard charucoBoard(int columns, int rows) {
  return {processing::BoardKind::kCharuco, {columns, rows}, cv::aruco::DICT_4X4_50, 0.7};
}

}  // namespace surroundd::calibration::testing
