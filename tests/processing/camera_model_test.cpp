// Lens models against OpenCV's own projection (OCamCalib's against the formula in
// ../shared/data/README.md), unproject as the inverse of project over the whole field of view, and
// the field cut where a lens's polynomial stops increasing.

#include "processing/lens/camera_model.hpp"

#include <filesystem>
#include <functional>
#include <numbers>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/persistence.hpp>

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

constexpr double kDegToRad = std::numbers::pi / 180;

// OCamCalib's rho(theta) coefficients for rho = sum q_k a^k in the off-axis angle a = theta + pi/2,
// so that the test lens is written in the angle it is easiest to think in (and rho is 0 on the
// axis).
std::vector<double> thetaPolynomial(const std::vector<double>& q) {
  std::vector<double> p(q.size(), 0.0);
  for (std::size_t k = 0; k < q.size(); ++k) {
    double binomial = 1;  // C(k, i)
    for (std::size_t i = 0; i <= k; ++i) {
      p[i] += q[k] * binomial * std::pow(std::numbers::pi / 2, static_cast<double>(k - i));
      binomial = binomial * static_cast<double>(k - i) / static_cast<double>(i + 1);
    }
  }
  return p;
}

// A 200-degree OCamCalib lens with a skewed affine matrix: rho = 320 a + 20 a^2 - 4 a^3 pixels.
Intrinsics ocam() {
  Intrinsics in;
  in.model = LensModel::kOcam;
  in.imageSize = {1280, 960};
  in.cx = 648.6;
  in.cy = 481.4;
  in.ocam.c = 1.002;
  in.ocam.d = 0.0015;
  in.ocam.e = -0.0008;
  in.ocam.worldToImage = thetaPolynomial({0, 320, 20, -4});
  in.maxFieldAngleRad = 100 * kDegToRad;
  return in;
}

// OCamCalib's image-to-world polynomial z(rho) for a lens, as OCamCalib fits it: least squares over
// the field (z = rho tan(theta) in its sensor frame), in rho / rhoMax for a well-posed fit.
std::vector<double> fitImageToWorld(const Intrinsics& in, int degree) {
  Intrinsics plain = in;  // rho itself: no affine matrix, centre at 0, the whole sphere
  plain.ocam.c = 1, plain.ocam.d = 0, plain.ocam.e = 0, plain.cx = 0, plain.cy = 0;
  plain.maxFieldAngleRad = std::numbers::pi;
  const CameraModel radial(plain);
  const auto rhoAt = [&](double a) { return radial.project({std::sin(a), 0, std::cos(a)})->x; };
  const double rhoMax = rhoAt(in.maxFieldAngleRad);
  const int samples = 400;
  cv::Mat design(samples, degree + 1, CV_64F);
  cv::Mat target(samples, 1, CV_64F);
  for (int i = 0; i < samples; ++i) {
    // Denser near the edge, where the fit is hardest; the last samples are a little past it.
    const double a =
        in.maxFieldAngleRad * 1.01 * std::sin(std::numbers::pi / 2 * i / (samples - 1));
    const double rho = rhoAt(a);
    target.at<double>(i) = i == 0 ? -radial.axisFocalPx()[0] : -rho / std::tan(a);
    for (int k = 0; k <= degree; ++k) design.at<double>(i, k) = std::pow(rho / rhoMax, k);
  }
  cv::Mat scaled;
  cv::solve(design, target, scaled, cv::DECOMP_SVD);
  std::vector<double> a;
  for (int k = 0; k <= degree; ++k) a.push_back(scaled.at<double>(k) / std::pow(rhoMax, k));
  return a;
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

// The formula ../shared/data/README.md gives, written out as it reads (Z > 0 only).
cv::Point2d readmeProjection(const Intrinsics& in, const cv::Vec3d& point) {
  const double x = point[0] / point[2];
  const double y = point[1] / point[2];
  const double r = std::sqrt(x * x + y * y);
  const double theta = std::atan(-1 / r);
  double rho = 0;
  for (std::size_t i = 0; i < in.ocam.worldToImage.size(); ++i) {
    rho += in.ocam.worldToImage[i] * std::pow(theta, static_cast<double>(i));
  }
  const auto& o = in.ocam;
  return {o.c * (x / r) * rho + o.d * (y / r) * rho + in.cx,
          o.e * (x / r) * rho + (y / r) * rho + in.cy};
}

TEST(CameraModel, OcamMatchesTheOcamCalibFormula) {
  const Intrinsics in = ocam();
  const CameraModel model(in);
  for (double degrees = 1; degrees < 90; degrees += 4) {
    for (const auto& ray : ring(degrees * kDegToRad)) {
      const auto pixel = model.project(ray * 1.7);
      ASSERT_TRUE(pixel) << degrees;
      const cv::Point2d expected = readmeProjection(in, ray);
      EXPECT_NEAR(pixel->x, expected.x, 1e-9) << degrees;
      EXPECT_NEAR(pixel->y, expected.y, 1e-9) << degrees;
    }
  }
  // The axis itself has no direction: the distortion centre.
  const auto centre = model.project({0, 0, 2});
  ASSERT_TRUE(centre);
  EXPECT_EQ(*centre, cv::Point2d(in.cx, in.cy));
}

TEST(CameraModel, OcamCarriesOnPastNinetyDegreesWithoutAJump) {
  const Intrinsics in = ocam();
  const CameraModel model(in);
  const auto at = [&](double degrees) {
    const double a = degrees * kDegToRad;
    return *model.project({std::sin(a) * 0.6, std::sin(a) * 0.8, std::cos(a)});
  };
  // At 90 degrees theta = 0, so rho = p0; just either side, the pixels close in on it.
  const auto& p = in.ocam.worldToImage;
  const cv::Point2d ninety = at(90);
  EXPECT_NEAR(ninety.x, in.cx + (in.ocam.c * 0.6 + in.ocam.d * 0.8) * p[0], 1e-9);
  EXPECT_NEAR(ninety.y, in.cy + (in.ocam.e * 0.6 + 0.8) * p[0], 1e-9);
  EXPECT_LT(cv::norm(at(90 - 1e-6) - ninety), 1e-3);
  EXPECT_LT(cv::norm(at(90 + 1e-6) - ninety), 1e-3);
  // Past 90 degrees: rho(theta) with theta = angle - 90 degrees, rho increasing on.
  double previous = 0;
  for (double degrees = 80; degrees <= 100; degrees += 1) {
    const double rho = cv::norm(at(degrees) - cv::Point2d(in.cx, in.cy));
    EXPECT_GT(rho, previous) << degrees;
    previous = rho;
  }
  EXPECT_FALSE(model.project({1, 0, -0.2}));  // 101 degrees: outside the 200-degree field
}

// Every pixel of the image circle (a grid over it) goes to a ray and back to the same pixel.
void expectPixelRoundTrip(const CameraModel& model, double toleranceRad) {
  const auto& in = model.intrinsics();
  int inside = 0;
  for (int y = -8; y < in.imageSize.height + 8; y += 7) {
    for (int x = -8; x < in.imageSize.width + 8; x += 7) {
      const cv::Point2d pixel(x + 0.25, y + 0.5);
      const auto ray = model.unproject(pixel);
      if (!ray) continue;
      ++inside;
      EXPECT_NEAR(cv::norm(*ray), 1, 1e-12);
      EXPECT_LE(std::acos(std::clamp((*ray)[2], -1.0, 1.0)), in.maxFieldAngleRad + toleranceRad);
      const auto back = model.project(*ray);
      ASSERT_TRUE(back) << pixel;
      EXPECT_LT(cv::norm(*back - pixel), 1e-3) << pixel;
    }
  }
  EXPECT_GT(inside, in.imageSize.area() / 49 / 2);
}

TEST(CameraModel, OcamRoundTripsOverTheWholeField) {
  const CameraModel model(ocam());
  expectRoundTrip(model, 100);
  expectPixelRoundTrip(model, 1e-12);
  // The rim of the field: 100 degrees exactly still has a pixel, and that pixel a ray.
  const auto rim = model.project({std::sin(100 * kDegToRad), 0, std::cos(100 * kDegToRad)});
  ASSERT_TRUE(rim);
  EXPECT_TRUE(model.unproject(*rim));
  EXPECT_FALSE(model.unproject(*rim + cv::Point2d(0.5, 0)));
}

TEST(CameraModel, OcamUnprojectsThroughItsImageToWorldPolynomial) {
  Intrinsics in = ocam();
  in.ocam.imageToWorld = fitImageToWorld(in, 14);
  ASSERT_LT(in.ocam.imageToWorld[0], 0);  // OCamCalib's sign: z < 0 in front of the lens
  const CameraModel model(in);
  expectPixelRoundTrip(model, 1e-5);
  for (double degrees = 0; degrees <= 100; degrees += 5) {
    for (const auto& ray : ring(degrees * kDegToRad)) {
      const auto back = model.unproject(*model.project(ray));
      ASSERT_TRUE(back) << degrees;
      EXPECT_LT(std::acos(std::min(1.0, back->dot(ray))), 1e-6) << degrees;
    }
  }
  // The polynomial is what unproject uses: a different one gives different rays.
  Intrinsics shifted = in;
  shifted.ocam.imageToWorld[0] *= 1.1;
  const cv::Point2d pixel(900, 300);
  EXPECT_GT(cv::norm(*CameraModel(shifted).unproject(pixel) - *model.unproject(pixel)), 1e-3);
}

TEST(CameraModel, AxisFocalLengths) {
  const Intrinsics f = fisheye();
  EXPECT_EQ(CameraModel(f).axisFocalPx(), cv::Vec2d(f.fx, f.fy));
  const Intrinsics o = ocam();
  const cv::Vec2d focal = CameraModel(o).axisFocalPx();
  EXPECT_NEAR(focal[0], 320 * std::hypot(o.ocam.c, o.ocam.e), 1e-9);
  EXPECT_NEAR(focal[1], 320 * std::hypot(o.ocam.d, 1.0), 1e-9);
}

TEST(CameraModel, AFieldCutByThePolynomialIsExposed) {
  EXPECT_FALSE(CameraModel(fisheye()).fieldCut());
  // Most pinhole calibrations turn somewhere (k3 < 0 here), mostly past the picture's corners.
  const auto pinholeTurn = CameraModel(pinhole()).fieldCut();
  ASSERT_TRUE(pinholeTurn);
  EXPECT_FALSE(pinholeTurn->inImage);
  EXPECT_FALSE(CameraModel(ocam()).fieldCut());

  // theta_d = theta (1 + 0.05 theta^2 - 0.05 theta^4) stops increasing where
  // 1 + 0.15 theta^2 - 0.25 theta^4 = 0: theta^2 = (0.15 + sqrt(1.0225)) / 0.5, 87.3 degrees.
  Intrinsics turning = fisheye();
  turning.distortion = {0.05, -0.05, 0, 0, 0};
  const CameraModel lens(turning);
  const auto cut = lens.fieldCut();
  ASSERT_TRUE(cut);
  const double turn = std::sqrt((0.15 + std::sqrt(1.0225)) / 0.5);
  EXPECT_NEAR(cut->atRad, turn, 95 * kDegToRad / 4000);
  EXPECT_LE(cut->atRad, turn);
  EXPECT_DOUBLE_EQ(cut->askedRad, 95 * kDegToRad);
  EXPECT_TRUE(cut->inImage);
  EXPECT_DOUBLE_EQ(lens.intrinsics().maxFieldAngleRad, cut->atRad);
  EXPECT_FALSE(lens.project(ring(88 * kDegToRad)[0]));
  EXPECT_TRUE(lens.project(ring(87 * kDegToRad)[0]));

  // An ocam lens: rho = 320 a - 60 a^3 turns at a = sqrt(320 / 180), 76.4 degrees.
  Intrinsics ocamTurning = ocam();
  ocamTurning.ocam.worldToImage = thetaPolynomial({0, 320, 0, -60});
  const auto ocamCut = CameraModel(ocamTurning).fieldCut();
  ASSERT_TRUE(ocamCut);
  EXPECT_NEAR(ocamCut->atRad, std::sqrt(320.0 / 180), 100 * kDegToRad / 4000);
  EXPECT_TRUE(ocamCut->inImage);

  // A pinhole whose distortion turns (r (1 - 0.3 r^2): at r = 1.054, distorted 0.703) beyond the
  // corners of its picture (0.61 at f = 1200) loses nothing of it.
  Intrinsics narrow = pinhole();
  narrow.distortion = {-0.3, 0, 0, 0, 0};
  narrow.fx = narrow.fy = 1200;
  const auto pinholeCut = CameraModel(narrow).fieldCut();
  ASSERT_TRUE(pinholeCut);
  EXPECT_NEAR(pinholeCut->atRad, std::atan(std::sqrt(1 / 0.9)), 1e-2);
  EXPECT_FALSE(pinholeCut->inImage);
  narrow.fx = narrow.fy = 540;
  EXPECT_TRUE(CameraModel(narrow).fieldCut()->inImage);
}

// A real lens calibrated with OCamCalib (../shared/data/pjlab-ocam-real, if present).
TEST(CameraModel, RealOcamCalibLensRoundTripsAtTheImageCircle) {
  const auto folder =
      std::filesystem::path(SURROUNDD_SOURCE_DIR) / "../shared/data/pjlab-ocam-real/intrinsic";
  if (!std::filesystem::exists(folder)) {
    GTEST_SKIP() << folder.lexically_normal().string() << " is absent (../shared/data)";
  }
  const cv::FileStorage file((folder / "Front.json").string(), cv::FileStorage::READ);
  ASSERT_TRUE(file.isOpened());
  const cv::FileNode param = file["front_camera-intrinsic"]["param"];
  const cv::FileNode k = param["cam_K"]["data"];
  Intrinsics in;
  in.model = LensModel::kOcam;
  in.imageSize = {static_cast<int>(param["img_dist_w"]), static_cast<int>(param["img_dist_h"])};
  in.ocam.c = static_cast<double>(k[0][0]);
  in.ocam.d = static_cast<double>(k[0][1]);
  in.ocam.e = static_cast<double>(k[1][0]);
  in.cx = static_cast<double>(k[0][2]);
  in.cy = static_cast<double>(k[1][2]);
  for (const auto& p : param["cam_dist"]["data"][0]) {
    in.ocam.worldToImage.push_back(static_cast<double>(p));
  }
  ASSERT_EQ(in.ocam.worldToImage.size(), 11U);
  in.maxFieldAngleRad = 110 * kDegToRad;
  const CameraModel model(in);
  EXPECT_FALSE(model.fieldCut());
  // The picture's image circle has a radius of about 620 pixels: there the lens sees about
  // 89 degrees off axis, the same all the way round.
  for (int i = 0; i < 72; ++i) {
    const double phi = 2 * std::numbers::pi * i / 72;
    const cv::Point2d pixel(in.cx + 620 * std::cos(phi), in.cy + 620 * std::sin(phi));
    const auto ray = model.unproject(pixel);
    ASSERT_TRUE(ray) << pixel;
    const double degrees = std::acos((*ray)[2]) / kDegToRad;
    EXPECT_NEAR(degrees, 89, 1) << pixel;
    const auto back = model.project(*ray);
    ASSERT_TRUE(back);
    EXPECT_LT(cv::norm(*back - pixel), 1e-3) << pixel;
  }
  expectPixelRoundTrip(model, 1e-12);
  EXPECT_NEAR(model.axisFocalPx()[1], 318.5, 0.5);
}

TEST(CameraModel, RaysOutsideTheLensHaveNoPixel) {
  const CameraModel lens(fisheye());
  EXPECT_FALSE(lens.project(cv::Vec3d(1, 0, -0.2)));  // 101 degrees off axis
  EXPECT_FALSE(lens.unproject(cv::Point2d(-2000, 361)));
  EXPECT_FALSE(CameraModel(pinhole()).project(cv::Vec3d(0.1, 0, -1)));
  const CameraModel wide(ocam());
  EXPECT_FALSE(wide.project(cv::Vec3d(1, 0, -0.2)));  // 101 degrees
  EXPECT_FALSE(wide.unproject(cv::Point2d(-2000, 481)));
}

// The lens's key (the LUT cache's) changes with every number of every model, and only with those:
// a parameter it left out would give a stale table with no error.
TEST(CameraModel, TheLensKeyChangesWithEveryParameter) {
  for (const LensModel model : kLensModels) {
    EXPECT_EQ(lensModelNamed(lensModelName(model)), model);
  }
  EXPECT_EQ(lensModelNamed("equidistant"), std::nullopt);
  EXPECT_FALSE(isWideAngle(LensModel::kPinhole));
  EXPECT_TRUE(isWideAngle(LensModel::kFisheye));
  EXPECT_TRUE(isWideAngle(LensModel::kOcam));

  Intrinsics base = ocam();
  base.fx = 300;
  base.fy = 301;
  base.distortion = {0.1, 0.2, 0.3, 0.4, 0.5};
  base.ocam.imageToWorld = {-200, 0, 1e-3};
  const std::string key = lensKey(base);
  EXPECT_EQ(lensKey(base), key);
  const std::vector<std::pair<const char*, std::function<void(Intrinsics&)>>> changes{
      {"model", [](Intrinsics& in) { in.model = LensModel::kFisheye; }},
      {"width", [](Intrinsics& in) { ++in.imageSize.width; }},
      {"height", [](Intrinsics& in) { ++in.imageSize.height; }},
      {"fx", [](Intrinsics& in) { in.fx = std::nextafter(in.fx, 1e9); }},
      {"fy", [](Intrinsics& in) { in.fy += 1e-9; }},
      {"cx", [](Intrinsics& in) { in.cx += 1e-9; }},
      {"cy", [](Intrinsics& in) { in.cy += 1e-9; }},
      {"k5", [](Intrinsics& in) { in.distortion[4] = 0.6; }},
      {"field", [](Intrinsics& in) { in.maxFieldAngleRad += 1e-9; }},
      {"c", [](Intrinsics& in) { in.ocam.c += 1e-9; }},
      {"d", [](Intrinsics& in) { in.ocam.d += 1e-9; }},
      {"e", [](Intrinsics& in) { in.ocam.e += 1e-9; }},
      {"world to image", [](Intrinsics& in) { in.ocam.worldToImage.back() *= 1.0000001; }},
      {"world to image's degree", [](Intrinsics& in) { in.ocam.worldToImage.push_back(0); }},
      {"image to world", [](Intrinsics& in) { in.ocam.imageToWorld.clear(); }},
  };
  for (const auto& [what, change] : changes) {
    Intrinsics changed = base;
    change(changed);
    EXPECT_NE(lensKey(changed), key) << what;
  }
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

// A quaternion turns as the mount angles do: yaw about +z, pitch about -y, roll about +x.
TEST(Rig, QuaternionTurnsAsTheMountAnglesDo) {
  const cv::Matx33d level = rotationFromMountAngles({});
  const auto about = [](double deg, const cv::Vec3d& axis) {
    const double half = deg * kDegToRad / 2;
    return cv::Vec4d(std::cos(half), std::sin(half) * axis[0], std::sin(half) * axis[1],
                     std::sin(half) * axis[2]);
  };
  for (const auto& [angles, quaternion] :
       {std::pair{MountAngles{90, 0, 0}, about(90, {0, 0, 1})},
        std::pair{MountAngles{0, -30, 0}, about(30, {0, 1, 0})},
        std::pair{MountAngles{0, 0, 12}, about(12, {1, 0, 0})}}) {
    EXPECT_LT(cv::norm(rotationFromQuaternion(quaternion) * level - rotationFromMountAngles(angles),
                       cv::NORM_INF),
              1e-12);
  }
}

}  // namespace
}  // namespace surroundd::processing
