// Lens models against OpenCV's own projection, and unproject as the inverse of project over the
// whole field of view.

#include "processing/camera_model.hpp"

#include <numbers>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "processing/rig.hpp"

namespace surroundd::processing {
namespace {

Intrinsics pinhole() {
  Intrinsics in;
  in.model = LensModel::kPinhole;
  in.imageSize = {1280, 720};
  in.fx = 540.2;
  in.fy = 538.7;
  in.cx = 641.3;
  in.cy = 358.9;
  in.distortion = {-0.12, 0.03, 0.0007, -0.0004, -0.004};
  return in;
}

Intrinsics fisheye() {
  Intrinsics in;
  in.model = LensModel::kFisheye;
  in.imageSize = {1280, 720};
  in.fx = 330.5;
  in.fy = 331.2;
  in.cx = 639.1;
  in.cy = 361.4;
  in.distortion = {0.05, -0.012, 0.002, -0.0003, 0};
  in.maxFieldAngleRad = 95.0 * std::numbers::pi / 180;
  return in;
}

// Directions at `angle` from the optical axis, all the way round.
std::vector<cv::Vec3d> ring(double angle) {
  std::vector<cv::Vec3d> rays;
  for (int i = 0; i < 24; ++i) {
    const double phi = 2 * std::numbers::pi * i / 24;
    rays.emplace_back(std::sin(angle) * std::cos(phi), std::sin(angle) * std::sin(phi),
                      std::cos(angle));
  }
  return rays;
}

TEST(CameraModel, PinholeMatchesOpenCv) {
  const Intrinsics in = pinhole();
  const CameraModel model(in);
  const cv::Matx33d k(in.fx, 0, in.cx, 0, in.fy, in.cy, 0, 0, 1);
  for (double degrees = 0; degrees <= 55; degrees += 5) {
    const auto rays = ring(degrees * std::numbers::pi / 180);
    std::vector<cv::Point3d> points(rays.begin(), rays.end());
    std::vector<cv::Point2d> expected;
    cv::projectPoints(points, cv::Vec3d(), cv::Vec3d(), k,
                      std::vector<double>(in.distortion.begin(), in.distortion.end()), expected);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const auto pixel = model.project(rays[i] * 3.7);
      ASSERT_TRUE(pixel) << degrees;
      EXPECT_NEAR(pixel->x, expected[i].x, 1e-6);
      EXPECT_NEAR(pixel->y, expected[i].y, 1e-6);
    }
  }
}

TEST(CameraModel, FisheyeMatchesOpenCv) {
  const Intrinsics in = fisheye();
  const CameraModel model(in);
  const cv::Matx33d k(in.fx, 0, in.cx, 0, in.fy, in.cy, 0, 0, 1);
  // OpenCV's fisheye model is defined in front of the camera; ours extends it past 90 degrees.
  for (double degrees = 0; degrees <= 85; degrees += 5) {
    const auto rays = ring(degrees * std::numbers::pi / 180);
    std::vector<cv::Point3d> points(rays.begin(), rays.end());
    std::vector<cv::Point2d> expected;
    cv::fisheye::projectPoints(
        points, expected, cv::Vec3d(), cv::Vec3d(), k,
        cv::Vec4d(in.distortion[0], in.distortion[1], in.distortion[2], in.distortion[3]));
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const auto pixel = model.project(rays[i] * 2.1);
      ASSERT_TRUE(pixel) << degrees;
      EXPECT_NEAR(pixel->x, expected[i].x, 1e-6);
      EXPECT_NEAR(pixel->y, expected[i].y, 1e-6);
    }
  }
}

void expectRoundTrip(const CameraModel& model, double maxDegrees) {
  for (double degrees = 0; degrees <= maxDegrees; degrees += 2.5) {
    for (const auto& ray : ring(degrees * std::numbers::pi / 180)) {
      const auto pixel = model.project(ray);
      ASSERT_TRUE(pixel) << degrees;
      const auto back = model.unproject(*pixel);
      ASSERT_TRUE(back) << degrees;
      EXPECT_LT(std::acos(std::min(1.0, back->dot(ray))), 1e-6) << degrees;
    }
  }
}

TEST(CameraModel, PinholeUnprojectInvertsProject) { expectRoundTrip(CameraModel(pinhole()), 55); }

TEST(CameraModel, FisheyeUnprojectInvertsProjectPastNinetyDegrees) {
  expectRoundTrip(CameraModel(fisheye()), 95);
}

TEST(CameraModel, RaysOutsideTheLensHaveNoPixel) {
  const CameraModel lens(fisheye());
  EXPECT_FALSE(lens.project(cv::Vec3d(1, 0, -0.2)));  // 101 degrees off axis
  EXPECT_FALSE(lens.unproject(cv::Point2d(-2000, 361)));
  EXPECT_FALSE(CameraModel(pinhole()).project(cv::Vec3d(0.1, 0, -1)));
}

TEST(Rig, MountAnglesRoundTrip) {
  for (const MountAngles angles : {MountAngles{0, -25, 0}, MountAngles{-90, -40, 3},
                                   MountAngles{180, -20, -2}, MountAngles{37, 12, 45}}) {
    const cv::Matx33d rotation = rotationFromMountAngles(angles);
    EXPECT_LT(cv::norm(rotation * rotation.t() - cv::Matx33d::eye(), cv::NORM_INF), 1e-12);
    EXPECT_LT(cv::norm(rotationFromMountAngles(mountAnglesFromRotation(rotation)) - rotation,
                       cv::NORM_INF),
              1e-12);
  }
  // Yaw 90 looks left (+y); pitch -30 looks down.
  const cv::Vec3d axis = rotationFromMountAngles({90, -30, 0}) * cv::Vec3d(0, 0, 1);
  EXPECT_NEAR(axis[1], std::cos(std::numbers::pi / 6), 1e-12);
  EXPECT_NEAR(axis[2], -0.5, 1e-12);
}

}  // namespace
}  // namespace surroundd::processing
