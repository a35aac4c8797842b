// Intrinsics from checkerboard views that the generator renders through a rig preset's own lens:
// the calibrated focal lengths must be within 0.5 % of the truth, for the paper's pinhole camera
// and the 190-degree fisheye.

#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "processing/calibration/calibration_coverage.hpp"
#include "processing/calibration/intrinsic_calibration.hpp"
#include "processing/calibration/target_detection.hpp"
#include "tests/calibration/calibration_test_support.hpp"

namespace surroundd::calibration::testing {
namespace {

const processing::Checkerboard kBoard{{9, 6}, 0.05};
constexpr int kViews = 20;

processing::IntrinsicCalibration calibrate(const processing::Intrinsics& truth,
                                           const std::vector<cv::Mat>& images) {
  std::vector<processing::BoardView> views;
  for (std::size_t i = 0; i < images.size(); ++i) {
    auto found = processing::findBoard(toGray(images[i]),
                                       {processing::BoardKind::kChessboard, kBoard.innerCorners});
    if (found.outcome == processing::BoardSearch::Outcome::kFound) {
      views.push_back(
          {"view " + std::to_string(i), std::move(found.corners), std::move(found.grid)});
    }
  }
  // The generator only makes views whose whole board is in the image and large enough.
  EXPECT_GE(views.size(), images.size() - 1);
  return processing::calibrateIntrinsics(truth.model, truth.imageSize, views);
}

void expectCloseToTruth(const processing::IntrinsicCalibration& result,
                        const processing::Intrinsics& truth) {
  const auto& in = result.intrinsics;
  const double fxErrorPercent = 100 * (in.fx / truth.fx - 1);
  const double fyErrorPercent = 100 * (in.fy / truth.fy - 1);
  EXPECT_LT(std::abs(fxErrorPercent), 0.5) << "fx " << in.fx << ", truth " << truth.fx;
  EXPECT_LT(std::abs(fyErrorPercent), 0.5) << "fy " << in.fy << ", truth " << truth.fy;
  EXPECT_NEAR(in.cx, truth.cx, 1.0);
  EXPECT_NEAR(in.cy, truth.cy, 1.0);
  EXPECT_LT(result.rmsPx, 0.2);
  for (const auto& view : result.views) EXPECT_LT(view.rmsPx, 0.4) << view.name;
  // The whole lens, distortion included: a ray lands within half a pixel of where the truth puts
  // it, over the part of the image the boards covered (the outer 10 % is extrapolation).
  const processing::CameraModel solved(in), exact(truth);
  double worst = 0;
  for (int row = 2; row <= 18; ++row) {
    for (int column = 2; column <= 18; ++column) {
      const cv::Point2d pixel(column * 0.05 * (truth.imageSize.width - 1),
                              row * 0.05 * (truth.imageSize.height - 1));
      const auto ray = exact.unproject(pixel);
      if (!ray || std::acos((*ray)[2]) > 80 * std::numbers::pi / 180) continue;
      worst = std::max(worst, cv::norm(*solved.project(*ray) - pixel));
    }
  }
  EXPECT_LT(worst, 0.5);
  ::testing::Test::RecordProperty("fx_error_percent", std::to_string(fxErrorPercent));
  ::testing::Test::RecordProperty("rms_px", std::to_string(result.rmsPx));
}

TEST(IntrinsicCalibration, PinholeOfThePaperRig) {
  const auto truth = presetCameras("paper.yaml").front().intrinsics;
  const auto result = calibrate(truth, boardViews(truth, kBoard, kViews, 3));
  expectCloseToTruth(result, truth);
}

TEST(IntrinsicCalibration, FisheyeOfTheProductionRig) {
  const auto truth = presetCameras("fisheye.yaml").front().intrinsics;
  const auto images = boardViews(truth, kBoard, kViews, 4);
  const auto result = calibrate(truth, images);
  expectCloseToTruth(result, truth);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(result.intrinsics.distortion[i], truth.distortion[i], 0.01) << "k" << i + 1;
  }
  // The image circle is inside the sensor: its lit area gives the lens's 190-degree field, exactly
  // through the true lens, and to a few degrees through the calibrated one, which there
  // extrapolates its polynomial from the 80 degrees the boards reach to 95.
  cv::Mat lit = cv::Mat::zeros(truth.imageSize, CV_8U);
  for (const auto& image : images) lit |= toGray(image) > 16;
  const double toDeg = 360 / std::numbers::pi;  // half-angle in radians to full field in degrees
  EXPECT_NEAR(processing::widestLitFieldAngle(truth, lit).rad * toDeg, 190, 0.5);
  EXPECT_NEAR(processing::widestLitFieldAngle(result.intrinsics, lit).rad * toDeg, 190, 5);
}

// A pinhole fit to a wide lens (Debian's opencv-doc right camera gave one) whose distortion turns
// back short of the image corners: those corners have no ray, and the field ends where the rays
// do, at the turn (k1 = -0.3: r (1 - 0.3 r^2) stops increasing at r = 1 / sqrt(0.9), 46.5 deg
// off the axis, 372 px out; the image corners are 400 px out). It was reported as 0.0 deg.
TEST(IntrinsicCalibration, APinholeWhoseDistortionTurnsShortOfTheCornersHasTheFieldToTheTurn) {
  processing::Intrinsics lens;
  lens.model = processing::LensModel::kPinhole;
  lens.imageSize = {640, 480};
  lens.fx = lens.fy = 530;
  lens.cx = 320, lens.cy = 240;
  lens.distortion = {-0.3, 0, 0, 0, 0};
  const processing::ImageCircle wholePicture{cv::Mat(lens.imageSize, CV_8U, cv::Scalar(255)),
                                             false};
  const double turnDeg = std::atan(1 / std::sqrt(0.9)) * 180 / std::numbers::pi;
  const auto lit = processing::widestLitFieldAngle(lens, wholePicture.lit);
  EXPECT_TRUE(lit.pastTheLens);
  EXPECT_NEAR(lit.rad * 180 / std::numbers::pi, turnDeg, 1.0);
  const auto field = processing::fieldOfViewOf(lens, wholePicture);
  EXPECT_NEAR(field.fullDeg, 2 * turnDeg, 2.0);
  EXPECT_FALSE(field.fromImageCircle);
  EXPECT_THAT(field.note, ::testing::HasSubstr("short of the picture's corners, the solved "
                                               "distortion stops increasing"));
  // Without the turn, the field runs to the image corners: atan(400 / 530) each way.
  lens.distortion = {};
  const auto straight = processing::fieldOfViewOf(lens, wholePicture);
  EXPECT_NEAR(straight.fullDeg, 2 * std::atan(400.0 / 530) * 180 / std::numbers::pi, 0.2);
  EXPECT_EQ(straight.note, "");
}

// Issue 47: fields of 193-200 degrees were written for lenses whose corners had reached 72
// degrees off the axis, past real image circles of 150-174. The field now ends a few degrees past
// the widest corner, and says so.
TEST(IntrinsicCalibration, TheFieldEndsAFewDegreesPastTheWidestCorner) {
  const auto lens = presetCameras("fisheye.yaml").front().intrinsics;
  const processing::ImageCircle wholePicture{cv::Mat(lens.imageSize, CV_8U, cv::Scalar(255)),
                                             false};
  const processing::CameraModel model(lens);
  // A view whose corners reach 60 degrees off the axis at most.
  const double reachRad = 60 * std::numbers::pi / 180;
  processing::BoardView view;
  for (const double angle : {0.0, reachRad / 2, reachRad}) {
    const auto pixel =
        model.project({std::sin(angle) * 0.6, std::sin(angle) * 0.8, std::cos(angle)});
    ASSERT_TRUE(pixel.has_value());
    view.corners.emplace_back(static_cast<float>(pixel->x), static_cast<float>(pixel->y));
  }
  const double widest = processing::widestCornerAngleRad(lens, {&view, 1});
  EXPECT_NEAR(widest, reachRad, 1e-4);
  const auto field = processing::fieldOfViewOf(lens, wholePicture, widest);
  EXPECT_NEAR(field.fullDeg, 2 * (60 + processing::kFieldPastCornersDeg), 0.01);
  EXPECT_FALSE(field.fromImageCircle);
  EXPECT_THAT(field.note, ::testing::HasSubstr("limited to 130.0 deg: the board's corners "
                                               "reached 60.0 deg off the axis"));
  // Corners at the picture's edge leave the field as the picture has it.
  const auto whole = processing::fieldOfViewOf(lens, wholePicture);
  EXPECT_EQ(
      processing::fieldOfViewOf(lens, wholePicture, whole.fullDeg * std::numbers::pi / 360).fullDeg,
      whole.fullDeg);
}

TEST(IntrinsicCalibration, TooFewViewsSaySoAndHowManyAreNeeded) {
  const auto truth = presetCameras("paper.yaml").front().intrinsics;
  const std::vector<processing::BoardView> views(
      3, {"a.png", std::vector<cv::Point2f>(54), std::vector<cv::Point>(54)});
  expectCalibrationError(
      [&] { processing::calibrateIntrinsics(truth.model, truth.imageSize, views); },
      "too few views: a board was found in 3 images, at least 5 are needed (from different angles "
      "and field positions)");
}

}  // namespace
}  // namespace surroundd::calibration::testing
