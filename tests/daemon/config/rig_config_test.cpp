// The rig's parts beyond cameras and sources: the vehicle (the car model, the views' and bowl's
// sizes, body masks) and the lens models (OCamCalib, a field cut by a lens's polynomial), read
// from the config with one message per mistake.

#include <limits>
#include <numbers>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "daemon/config/config.hpp"
#include "tests/daemon/config/config_test_support.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {
namespace {

using ::testing::HasSubstr;

// The vehicle: one block that sizes the car model, the views and the bowl, in the config or in
// the rig file (the config's wins).
TEST_F(ConfigTest, TheVehicleSizesTheCarTheViewsAndTheBowl) {
  const Config car = loadConfig(dir_.write("config.yaml", std::string(kGoodConfig)));
  EXPECT_EQ(car.vehicle, std::nullopt);
  EXPECT_DOUBLE_EQ(car.car().lengthM, 4.5);
  const Config robot = loadConfig(dir_.write(
      "config.yaml",
      std::string(kGoodConfig) +
          "vehicle: {length_m: 0.5, width_m: 0.4, height_m: 0.3, ground_clearance_m: 0.05, "
          "front_overhang_m: 0.1, rear_overhang_m: 0.1, x_m: 0.1, margin_m: 0.05}\n"));
  ASSERT_TRUE(robot.vehicle.has_value());
  EXPECT_TRUE(robot.car().model.empty());
  const std::filesystem::path model =
      std::filesystem::path(SURROUNDD_SOURCE_DIR) / "tests/render/models/test_car.gltf";
  const Config modelled = loadConfig(dir_.write(
      "modelled.yaml", std::string(kGoodConfig) + "vehicle: {model: " + model.string() + "}\n"));
  EXPECT_EQ(modelled.car().model, model);
  EXPECT_DOUBLE_EQ(robot.car().lengthM, 0.5);
  EXPECT_DOUBLE_EQ(robot.car().box().centreXM, 0.1);
  EXPECT_DOUBLE_EQ(robot.car().marginM, 0.05);
  // A small vehicle gets a close look; a car the familiar 8 m.
  EXPECT_LT(robot.render.views.topRangeM, 2.0);
  EXPECT_NEAR(car.render.views.topRangeM, 8.0, 0.1);
  EXPECT_LT(robot.render.views.orbitRadiusM, car.render.views.orbitRadiusM / 3);
  // The bowl's floor reaches the top view's corners, so that the ground it shows stays flat.
  for (const Config* config : {&car, &robot}) {
    EXPECT_NEAR(config->mesh.bowlFloorRadiusM, topViewReachM(config->render), 1e-9);
    EXPECT_GT(config->mesh.bowlRadiusM, config->mesh.bowlFloorRadiusM);
    EXPECT_TRUE(config->warnings.empty()) << ::testing::PrintToString(config->warnings);
  }
  // A floor set smaller than that is allowed, with a warning.
  const Config small = loadConfig(
      dir_.write("config.yaml",
                 std::string(kGoodConfig) + "mesh: {bowl_floor_radius_m: 5, bowl_radius_m: 10}\n"));
  ASSERT_EQ(small.warnings.size(), 1u);
  EXPECT_THAT(small.warnings[0], HasSubstr("mesh.bowl_floor_radius_m 5 is less than"));
}

TEST_F(ConfigTest, VehicleAndBodyMaskMistakesAreNamed) {
  expectOneError(
      "capture:", "vehicle: {length_m: 4, footprint: [[1, 1], [-1, 1], [0, -1]]}\ncapture:",
      {"vehicle.footprint", "either length_m and width_m or footprint"});
  expectOneError("capture:", "vehicle: {footprint: [[1, 1], [-1, 1]]}\ncapture:",
                 {"vehicle.footprint", "at least 3 [x, y] pairs", "2 items"});
  expectOneError("capture:", "vehicle: {height_m: 1, ground_clearance_m: 1.2}\ncapture:",
                 {"vehicle.ground_clearance_m", "less than height_m"});
  expectOneError("capture:", "vehicle: {length_m: 1, front_overhang_m: 0.6}\ncapture:",
                 {"vehicle.front_overhang_m", "no wheelbase"});
  // The car's own model is read whole at load, so that --check-config finds what cannot be drawn.
  dir_.write("car.gltf", "{\"asset\": {\"version\": \"2.0\"}}");
  expectOneError("capture:", "vehicle: {model: car.gltf}\ncapture:",
                 {"vehicle.model", "car.gltf", "no scene"});
  expectOneError(
      "capture:", "vehicle: {model: nowhere.glb}\ncapture:", {"vehicle.model", "nowhere.glb"});
  expectOneError("      source: {file: left.mkv}",
                 "      source: {file: left.mkv}\n      body_mask: {mode: add}",
                 {"body_mask", "expected 'file'"});
  expectOneError("      source: {file: left.mkv}",
                 "      source: {file: left.mkv}\n      body_mask: {file: nowhere.png}",
                 {"body_mask.file", "nowhere.png"});
  cv::imwrite((dir_ / "small.png").string(), cv::Mat(10, 20, CV_8U, cv::Scalar(255)));
  expectOneError("      source: {file: left.mkv}",
                 "      source: {file: left.mkv}\n      body_mask: {file: small.png}",
                 {"body_mask.file", "expected a 640x360 picture", "got 20x10"});
  expectOneError("  height_px: 360\noutputs", "  height_px: 360\n  car_length_m: 4\noutputs",
                 {"render.car_length_m", "vehicle.length_m"});
}

// An OCamCalib lens (pjlab-ocam-real's front camera, at the test's image size).
constexpr std::string_view kFisheyeLens =
    "lens: {model: fisheye, width_px: 640, height_px: 360, fx_px: 200, fy_px: 200, cx_px: 320, "
    "cy_px: 180, distortion: [0.01, 0, 0, 0]}";
constexpr std::string_view kOcamLens =
    "lens: {model: ocam, width_px: 640, height_px: 360, cx_px: 324.2996405915, cy_px: 180.68, "
    "affine: [0.999838380441138, 0.0004930391795583601, 0.0002399186063006992], "
    "world_to_image: [313.9637388881135, 233.0140385143145, -1.44933146544235, 12.1110306359207, "
    "36.3475315711723, -16.6900244711004, -11.7592608095917, 57.1126396050695, 69.6739047998985, "
    "30.5611743664997, 4.842027746453106], field_of_view_deg: 200}";

TEST_F(ConfigTest, AnOcamLensIsReadAndWrittenBackExactly) {
  std::string lens(kOcamLens);
  const Config config = loadConfig(configWith(kFisheyeLens, lens));
  const auto& in = config.cameras[1].calibration.intrinsics;
  EXPECT_EQ(in.model, processing::LensModel::kOcam);
  EXPECT_EQ(in.cx, 324.2996405915);
  EXPECT_EQ(in.ocam.c, 0.999838380441138);
  EXPECT_EQ(in.ocam.d, 0.0004930391795583601);
  EXPECT_EQ(in.ocam.e, 0.0002399186063006992);
  ASSERT_EQ(in.ocam.worldToImage.size(), 11U);
  EXPECT_EQ(in.ocam.worldToImage[10], 4.842027746453106);
  EXPECT_TRUE(in.ocam.imageToWorld.empty());
  EXPECT_DOUBLE_EQ(in.maxFieldAngleRad * 360 / std::numbers::pi, 200);
  EXPECT_EQ(in.fx, 0);  // unused by ocam
  EXPECT_TRUE(processing::CameraModel(in).unproject({600, 300}));

  // Through a rig file and back, with and without the image-to-world polynomial.
  lens.replace(lens.find(", field_of_view_deg"), 0,
               ", image_to_world: [-159.23, 0, 0.0006871342, -3.1e-07, 5.5e-10]");
  auto withPolynomial = loadConfig(configWith(kFisheyeLens, lens)).cameras;
  EXPECT_EQ(withPolynomial[1].calibration.intrinsics.ocam.imageToWorld.size(), 5U);
  for (const auto& cameras : {config.cameras, withPolynomial}) {
    writeRigFile(dir_ / "rig.yaml", cameras, "test");
    const auto back = loadRigFile(dir_ / "rig.yaml");
    EXPECT_EQ(back[1].calibration.intrinsics, cameras[1].calibration.intrinsics);
    EXPECT_EQ(back[0].calibration.intrinsics, cameras[0].calibration.intrinsics);
  }
}

TEST_F(ConfigTest, AnOcamLensRefusesWhatItDoesNotTake) {
  const std::string lens(kOcamLens);
  const auto with = [&](std::string_view from, std::string_view to) {
    std::string text = lens;
    text.replace(text.find(from), from.size(), to);
    return text;
  };
  // The lens with its world_to_image list replaced by `list`, or the key dropped.
  const auto withPolynomial = [&](std::string_view list) {
    std::string text = lens;
    const auto begin = text.find("world_to_image");
    text.replace(begin, text.find("field_of_view_deg") - begin, list);
    return text;
  };
  const auto expectError = [&](const std::string& text, std::string_view part) {
    const auto messages = errorsOf(configWith(kFisheyeLens, text));
    ASSERT_EQ(messages.size(), 1U) << ::testing::PrintToString(messages);
    EXPECT_THAT(messages[0], HasSubstr(std::string(part)));
    EXPECT_THAT(messages[0], HasSubstr(where(11, 1).substr(0, where(11, 1).size() - 1)));
  };
  expectError(with("cx_px", "fx_px: 300, cx_px"),
              "rig.cameras[1].lens.fx_px: an ocam lens does not take this key");
  expectError(with("affine", "distortion: [0, 0, 0, 0], affine"),
              "rig.cameras[1].lens.distortion: an ocam lens does not take this key");
  expectError(withPolynomial(""), "rig.cameras[1].lens: missing key 'world_to_image'");
  expectError(withPolynomial("world_to_image: [1], "),
              "rig.cameras[1].lens.world_to_image: expected a list of 2 to 32 numbers, got 1 "
              "items");
  expectError(with("affine: [0.999838380441138", "affine: [0"),
              "rig.cameras[1].lens.affine: expected [c, d, e] of an invertible matrix [c d; e 1]");
  expectError(with("field_of_view_deg", "image_to_world: [159.2, 0, 0.0007], field_of_view_deg"),
              "rig.cameras[1].lens.image_to_world: expected OCamCalib's a0 < 0 first");
  const auto messages = errorsOf(
      configWith("distortion: [0.01, 0, 0, 0]", "distortion: [0.01, 0, 0, 0], affine: [1, 0, 0]"));
  ASSERT_EQ(messages.size(), 1U) << ::testing::PrintToString(messages);
  EXPECT_THAT(messages[0],
              HasSubstr("rig.cameras[1].lens.affine: only an ocam lens takes this key"));
}

// --check-config said "good" for these, then the camera saw a pinpoint and start failed
// (issue 18.11).
TEST_F(ConfigTest, DistortionNoLensHasIsRefusedNamingTheCameraAndCoefficient) {
  expectOneError("distortion: [0.01, 0, 0, 0]", "distortion: [1e300, 0, 0, 0]",
                 {"rig.cameras[1].lens.distortion",
                  "camera 'left': k1 = 1e+300 is no lens's "
                  "distortion (expected within -1000 to 1000)"});
  expectOneError("distortion: [0.01, 0, 0, 0]", "distortion: [0.01, 0, 0, -2e3]",
                 {"camera 'left': k4 = -2000"});
  expectOneError("cx_px: 319.5, cy_px: 179.5}",
                 "cx_px: 319.5, cy_px: 179.5, distortion: [0, 0, 0, 0, 1e300]}",
                 {"rig.cameras[0].lens.distortion", "camera 'front': k3 = 1e+300"});
  // Within the bounds, but no lens: the picture's edge would be 7 degrees off axis, not 47.
  expectOneError("cx_px: 319.5, cy_px: 179.5}",
                 "cx_px: 319.5, cy_px: 179.5, distortion: [900, 0, 0, 0, 0]}",
                 {"rig.cameras[0].lens.distortion",
                  "camera 'front': with this distortion the "
                  "picture's edge is"});
  // Strong, real distortion passes: a wide pinhole's barrel and a fisheye's terms.
  EXPECT_TRUE(errorsOf(configWith("cx_px: 319.5, cy_px: 179.5}",
                                  "cx_px: 319.5, cy_px: 179.5, distortion: [-0.3, 0.1, 0.001, "
                                  "-0.001, -0.02]}"))
                  .empty());
  EXPECT_TRUE(
      errorsOf(configWith("distortion: [0.01, 0, 0, 0]", "distortion: [-0.05, 0.02, -0.01, 0.002]"))
          .empty());
}

TEST_F(ConfigTest, ALensFieldCutByItsPolynomialIsNamedWithItsCameraAndAngle) {
  const Config plain = loadConfig(configWith("", ""));
  for (const auto& camera : plain.cameras) EXPECT_FALSE(lensFieldCutWarning(camera.calibration));
  // theta_d = theta (1 + 0.05 theta^2 - 0.05 theta^4) turns at 87.3 degrees, inside the picture.
  const Config turning = loadConfig(configWith(
      "distortion: [0.01, 0, 0, 0]", "distortion: [0.05, -0.05, 0, 0], field_of_view_deg: 190"));
  const auto warning = lensFieldCutWarning(turning.cameras[1].calibration);
  ASSERT_TRUE(warning);
  EXPECT_EQ(*warning,
            "camera 'left': the lens's distortion polynomial stops increasing 87.3 degrees off "
            "axis, so its field is cut there (field_of_view_deg asks for 190.0 degrees); the "
            "picture beyond that circle is not used");
}

// Issue 51: an import gave a calibration a NaN and wrote it, exiting 0; the daemon refused the rig
// at its next start. writeRigFile refuses it, naming where, and leaves the file as it was.
TEST_F(ConfigTest, ARigWithANumberThatIsNotFiniteIsNotWritten) {
  const Config config = loadConfig(configWith(kFisheyeLens, std::string(kOcamLens)));
  writeRigFile(dir_ / "rig.yaml", config.cameras, "good");
  const std::string before = testing::fileBytes(dir_ / "rig.yaml");
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::infinity()}) {
    auto cameras = config.cameras;
    cameras[1].calibration.intrinsics.ocam.worldToImage[3] = bad;
    EXPECT_THAT([&] { writeRigFile(dir_ / "rig.yaml", cameras, "bad"); },
                ::testing::ThrowsMessage<ConfigError>(
                    HasSubstr("rig.yaml: not written: cameras[1].lens.world_to_image[3] is not a "
                              "finite number")));
    cameras = config.cameras;
    cameras[0].calibration.pose.position[2] = bad;
    EXPECT_THAT([&] { writeRigFile(dir_ / "rig.yaml", cameras, "bad"); },
                ::testing::ThrowsMessage<ConfigError>(HasSubstr("cameras[0].mount.z_m")));
  }
  EXPECT_EQ(testing::fileBytes(dir_ / "rig.yaml"), before);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "rig.yaml.part"));
}

}  // namespace
}  // namespace surroundd::daemon
