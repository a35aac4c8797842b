// Config validation: a good config loads to the expected values, and each class of mistake gives
// one message that names the file, line, column, key path and what was expected.

#include "daemon/config.hpp"

#include <fstream>
#include <numbers>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "tests/support/temp_dir.hpp"

namespace surroundd::daemon {
namespace {

using ::testing::HasSubstr;

// Two cameras are enough for the schema; line numbers below refer to this text.
constexpr std::string_view kGoodConfig = R"(logging:
  level: debug
rig:
  cameras:
    - name: front
      source: {file: front.mkv}
      lens: {model: pinhole, width_px: 640, height_px: 360, fx_px: 300, fy_px: 300, cx_px: 319.5, cy_px: 179.5}
      mount: {x_m: 1.0, y_m: 0.0, z_m: 1.8, yaw_deg: 0, pitch_deg: -20}
    - name: left
      source: {file: left.mkv}
      lens: {model: fisheye, width_px: 640, height_px: 360, fx_px: 200, fy_px: 200, cx_px: 320, cy_px: 180, distortion: [0.01, 0, 0, 0]}
      mount: {x_m: 0.0, y_m: 0.9, z_m: 1.0, yaw_deg: 90, pitch_deg: -40}
capture:
  pacing: as_fast_as_possible
  sync_tolerance_ms: 5
render:
  width_px: 640
  height_px: 360
outputs:
  - {type: video, path: out/mosaic.mp4, crf: 18}
  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}
)";

class ConfigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_.write("front.mkv", "");
    dir_.write("left.mkv", "");
  }

  // The good config with both cameras live: front on /dev/video0, left's source as given.
  std::filesystem::path liveConfigWith(std::string_view leftSource) {
    std::string text(kGoodConfig);
    const auto replace = [&](std::string_view from, std::string_view to) {
      text.replace(text.find(from), from.size(), to);
    };
    replace("source: {file: front.mkv}", "source: {device: /dev/video0}");
    replace("source: {file: left.mkv}", leftSource);
    return dir_.write("config.yaml", text);
  }

  // The good config with `from` replaced by `to` (which must occur).
  std::filesystem::path configWith(std::string_view from, std::string_view to) {
    std::string text(kGoodConfig);
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return dir_.write("config.yaml", text);
  }

  // The messages loadConfig throws for `file`; empty if it loads.
  static std::vector<std::string> errorsOf(const std::filesystem::path& file) {
    try {
      loadConfig(file);
    } catch (const ConfigError& e) {
      return e.messages();
    }
    return {};
  }

  // Exactly one message, which must contain every part.
  void expectOneError(std::string_view from, std::string_view to,
                      std::initializer_list<std::string_view> parts) {
    const auto file = configWith(from, to);
    const auto messages = errorsOf(file);
    ASSERT_EQ(messages.size(), 1u) << ::testing::PrintToString(messages);
    for (const auto part : parts) EXPECT_THAT(messages[0], HasSubstr(std::string(part)));
  }

  std::string where(int line, int column) const {
    return (dir_ / "config.yaml").string() + ":" + std::to_string(line) + ":" +
           std::to_string(column);
  }

  testing::TempDir dir_;
};

TEST_F(ConfigTest, GoodConfigLoads) {
  const Config config = loadConfig(configWith("", ""));
  EXPECT_EQ(config.logLevel, spdlog::level::debug);
  ASSERT_EQ(config.cameras.size(), 2u);
  const auto& front = config.cameras[0];
  EXPECT_EQ(front.calibration.name, "front");
  EXPECT_EQ(front.source->path, dir_ / "front.mkv");  // relative to the config's folder
  EXPECT_EQ(front.calibration.role, processing::ColourRole::kSource);
  EXPECT_EQ(config.cameras[1].calibration.role, processing::ColourRole::kTarget);
  EXPECT_EQ(config.cameras[1].calibration.intrinsics.model, processing::LensModel::kFisheye);
  // Pitched down 20 degrees, looking forward: the optical axis is (cos 20, 0, -sin 20).
  const cv::Vec3d axis = front.calibration.pose.rotation * cv::Vec3d(0, 0, 1);
  EXPECT_NEAR(axis[0], std::cos(20 * CV_PI / 180), 1e-12);
  EXPECT_NEAR(axis[2], -std::sin(20 * CV_PI / 180), 1e-12);
  EXPECT_EQ(config.capture.pacing, capture::Pacing::kAsFastAsPossible);
  EXPECT_DOUBLE_EQ(config.capture.syncToleranceMs, 5.0);
  ASSERT_EQ(config.outputs.size(), 2u);
  EXPECT_EQ(config.outputs[0].path, dir_ / "out/mosaic.mp4");
  EXPECT_EQ(config.outputs[0].crf, 18);
  EXPECT_EQ(config.outputs[1].kind, OutputKind::kSnapshot);
  EXPECT_DOUBLE_EQ(config.outputs[1].atSeconds, 0.5);
  EXPECT_EQ(config.panorama.widthPx, PanoramaConfig{}.widthPx);  // absent sections keep defaults
}

TEST_F(ConfigTest, ColourCorrectionSettingsAreRead) {
  std::string text(kGoodConfig);
  text += "colour_correction: {field: additive, solver: cholmod, scale: 0.125}\n";
  const Config config = loadConfig(dir_.write("config.yaml", text));
  EXPECT_EQ(config.colour.method, ColourMethod::kPoisson);
  EXPECT_EQ(config.colour.poisson.field, CorrectionField::kAdditive);
  EXPECT_EQ(config.colour.poisson.solver, PoissonSolverKind::kCholmod);
  EXPECT_DOUBLE_EQ(config.colour.poisson.scale, 0.125);
  const auto messages = errorsOf(
      dir_.write("config.yaml", std::string(kGoodConfig) + "colour_correction: {field: ratio}\n"));
  ASSERT_EQ(messages.size(), 1u) << ::testing::PrintToString(messages);
  EXPECT_THAT(messages[0],
              HasSubstr("colour_correction.field: expected one of 'multiplicative' 'additive'"));
}

TEST_F(ConfigTest, SurroundOutputsTakeTheirOwnViewOrTheRenderDefault) {
  const Config config = loadConfig(configWith("  height_px: 360\n", R"(  height_px: 360
  view: top
  split_camera: left
  orbit_period_s: 12
  platform: surfaceless
)"));
  const auto file = configWith("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                               R"(  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}
  - {type: video, stream: surround, path: out/orbit.mp4}
  - {type: snapshot, stream: surround, view: 360, path: out/360.png})");
  const Config surround = loadConfig(file);
  ASSERT_EQ(surround.outputs.size(), 4u);
  EXPECT_EQ(surround.outputs[2].stream, OutputStream::kSurround);
  EXPECT_EQ(surround.outputs[2].view, std::nullopt);  // render.view
  EXPECT_EQ(surround.outputs[3].view, ViewKind::kPanorama360);
  EXPECT_EQ(config.render.view, ViewKind::kTop);
  EXPECT_EQ(config.render.splitCamera, "left");
  EXPECT_DOUBLE_EQ(config.render.views.orbitPeriodS, 12.0);
  EXPECT_EQ(config.render.platform, render::EglPlatform::kSurfaceless);
}

TEST_F(ConfigTest, ALiveCameraIsAV4l2DeviceOfTheLensSize) {
  const Config config = loadConfig(liveConfigWith(
      "source: {device: /dev/v4l/by-path/pci-0000:00:14.0-usb-0:1:1.0-video-index0, format: "
      "mjpeg, fps: 25, timeout_ms: 300, controls: {gain: 40, exposure_auto: 1}}"));
  const auto& left = config.cameras[1];
  EXPECT_FALSE(left.source.has_value());
  ASSERT_TRUE(left.device.has_value());
  EXPECT_EQ(left.device->device, "/dev/v4l/by-path/pci-0000:00:14.0-usb-0:1:1.0-video-index0");
  EXPECT_EQ(left.device->format, capture::V4l2Format::kMjpeg);
  EXPECT_EQ(left.device->size, cv::Size(640, 360));
  EXPECT_DOUBLE_EQ(left.device->fps, 25.0);
  EXPECT_EQ(left.device->timeout, std::chrono::milliseconds(300));
  EXPECT_EQ(left.device->controls,
            (std::vector<capture::V4l2Control>{{"exposure_auto", 1}, {"gain", 40}}));

  // And back through a rig file.
  writeRigFile(dir_ / "rig.yaml", config.cameras, "test");
  const auto cameras = loadRigFile(dir_ / "rig.yaml");
  ASSERT_TRUE(cameras[1].device.has_value());
  EXPECT_EQ(*cameras[1].device, *left.device);
}

TEST_F(ConfigTest, ALiveCameraWithAnUnknownFormatOrControlOrMixedWithFilesIsRefused) {
  for (const auto& [source, message] :
       {std::pair{"source: {device: /dev/video3, format: h264}", "rig.cameras[1].source.format"},
        std::pair{"source: {device: /dev/video3, controls: {shutter_speed: 3}}",
                  "rig.cameras[1].source.controls.shutter_speed: unknown key"},
        std::pair{"source: {file: left.mkv}",
                  "mixes live devices and files: the cameras of a rig are either all live or all "
                  "replayed"}}) {
    const auto messages = errorsOf(liveConfigWith(source));
    ASSERT_EQ(messages.size(), 1u) << ::testing::PrintToString(messages);
    EXPECT_THAT(messages[0], HasSubstr(message));
  }
}

TEST_F(ConfigTest, ALibcameraCameraIsNamedByItsId) {
  const Config config = loadConfig(liveConfigWith("source: {libcamera: imx219@10, fps: 25}"));
  const auto& left = config.cameras[1];
  ASSERT_TRUE(left.libcamera.has_value());
  EXPECT_EQ(left.libcamera->camera, "imx219@10");
  EXPECT_EQ(left.libcamera->size, cv::Size(640, 360));
  EXPECT_DOUBLE_EQ(left.libcamera->fps, 25.0);
  writeRigFile(dir_ / "rig.yaml", config.cameras, "test");
  EXPECT_EQ(*loadRigFile(dir_ / "rig.yaml")[1].libcamera, *left.libcamera);
}

TEST_F(ConfigTest, ARecordingIsAFolder) {
  const Config config =
      loadConfig(configWith("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                            "  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}\n"
                            "  - {type: recording, path: out/drive, lossless: false, crf: 20}"));
  ASSERT_EQ(config.outputs.size(), 3u);
  EXPECT_EQ(config.outputs[2].kind, OutputKind::kRecording);
  EXPECT_EQ(config.outputs[2].path, dir_ / "out/drive");
  EXPECT_FALSE(config.outputs[2].lossless);
  EXPECT_EQ(config.outputs[2].crf, 20);
  expectOneError("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: recording, path: front.mkv}",
                 {"outputs[1].path: expected a folder for the recording, got the file"});
  expectOneError("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: recording, stream: panorama, path: out/drive}",
                 {"outputs[1].stream: a recording writes every camera's own stream"});
}

TEST_F(ConfigTest, SegmentedVideoNetworkStreamAndTheControlSocket) {
  const Config config = loadConfig(
      configWith("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: video, path: out/drive.mkv, segment_s: 60}\n"
                 "  - {type: network, stream: surround, url: \"udp://239.0.0.1:5600\", crf: 28}\n"
                 "control: {socket: run/control.sock}"));
  ASSERT_EQ(config.outputs.size(), 3u);
  EXPECT_DOUBLE_EQ(config.outputs[1].segmentS, 60.0);
  EXPECT_EQ(config.outputs[2].kind, OutputKind::kNetwork);
  EXPECT_EQ(config.outputs[2].url, "udp://239.0.0.1:5600");
  EXPECT_EQ(config.outputs[2].crf, 28);
  EXPECT_TRUE(config.outputs[2].path.empty());
  EXPECT_EQ(config.control.socket, dir_ / "run/control.sock");
  const Config pages = loadConfig(
      configWith("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: http, stream: surround, listen: \"0.0.0.0:9000\", quality: 60}\n"
                 "  - {type: window, display: \":3\", title: rig}\n"
                 "  - {type: http, stream: mosaic}\n"
                 "  - {type: display, stream: surround, device: /dev/dri/card1, "
                 "connector: HDMI-A-1}"));
  ASSERT_EQ(pages.outputs.size(), 5u);
  EXPECT_EQ(pages.outputs[1].kind, OutputKind::kHttp);
  EXPECT_EQ(pages.outputs[1].listenAddress, "0.0.0.0");
  EXPECT_EQ(pages.outputs[1].listenPort, 9000);
  EXPECT_EQ(pages.outputs[1].jpegQuality, 60);
  EXPECT_EQ(pages.outputs[2].kind, OutputKind::kWindow);
  EXPECT_EQ(pages.outputs[2].display, ":3");
  EXPECT_EQ(pages.outputs[2].title, "rig");
  EXPECT_EQ(pages.outputs[3].listenAddress, "127.0.0.1");  // only this machine by default
  EXPECT_EQ(pages.outputs[3].listenPort, 8080);
  EXPECT_EQ(pages.outputs[4].kind, OutputKind::kDisplay);
  EXPECT_EQ(pages.outputs[4].device, "/dev/dri/card1");
  EXPECT_EQ(pages.outputs[4].connector, "HDMI-A-1");
  expectOneError(
      "  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
      "  - {type: http, listen: \"localhost\"}",
      {"outputs[1].listen: expected IPv4-ADDRESS:PORT (e.g. 127.0.0.1:8080), got 'localhost'"});
  expectOneError("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: http, listen: \"localhost:8080\"}", {"got 'localhost:8080'"});
  expectOneError("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: network, url: \"http://example.com\"}",
                 {"outputs[1].url: expected udp://HOST:PORT, got 'http://example.com'"});
  expectOneError("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: video, path: out/a.mp4, segment_s: -1}",
                 {"outputs[1].segment_s: expected a number in [0, 86400]"});
  expectOneError("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: snapshot, path: out/b.png, segment_s: 5}",
                 {"outputs[1].segment_s: unknown key"});
}

TEST_F(ConfigTest, AViewOnlyBelongsToASurroundOutput) {
  expectOneError("{type: snapshot, path: out/mosaic.png,",
                 "{type: snapshot, view: top, path: out/mosaic.png,",
                 {"outputs[1].view: only a surround output has a view"});
}

TEST_F(ConfigTest, SplitCameraMustBeACamera) {
  expectOneError("  height_px: 360\n", "  height_px: 360\n  split_camera: rear\n",
                 {"render.split_camera: no camera is named 'rear'"});
}

TEST_F(ConfigTest, UnknownKey) {
  expectOneError("  sync_tolerance_ms: 5", "  sync_tolerance_ms: 5\n  sync_tolerence_ms: 5",
                 {where(16, 3),
                  "capture.sync_tolerence_ms: unknown key (expected one of:", "sync_tolerance_ms"});
}

TEST_F(ConfigTest, WrongType) {
  expectOneError("width_px: 640\n  height", "width_px: wide\n  height",
                 {where(17, 13), "render.width_px: expected a whole number", "'wide'"});
}

TEST_F(ConfigTest, OutOfRange) {
  expectOneError("sync_tolerance_ms: 5", "sync_tolerance_ms: -3",
                 {where(15, 22), "capture.sync_tolerance_ms: expected a number in [0, 1000]",
                  "milliseconds", "-3"});
}

TEST_F(ConfigTest, MissingFile) {
  expectOneError("{file: left.mkv}", "{file: lfet.mkv}",
                 {"rig.cameras[1].source.file: expected an existing video file",
                  (dir_ / "lfet.mkv").string(), "no such file"});
}

// A still picture loops unless told not to, at sequence_fps; the frozen check is set per camera.
TEST_F(ConfigTest, StillPicturesLoopAndTheFrozenCheckIsPerCamera) {
  dir_.write("front.png", "");
  const Config config = loadConfig(configWith(
      "source: {file: front.mkv}\n",
      "source: {file: front.png, sequence_fps: 10}\n      health: {frozen_check: on}\n"));
  ASSERT_TRUE(config.cameras[0].source.has_value());
  EXPECT_TRUE(config.cameras[0].source->loop);
  EXPECT_EQ(config.cameras[0].source->sequenceFps, 10.0);
  EXPECT_EQ(config.cameras[0].frozenCheck, FrozenCheck::kOn);
  EXPECT_FALSE(config.cameras[1].source->loop);  // a video plays once by default
  EXPECT_EQ(config.cameras[1].frozenCheck, FrozenCheck::kAuto);

  const Config once =
      loadConfig(configWith("source: {file: front.mkv}", "source: {file: front.png, loop: false}"));
  EXPECT_FALSE(once.cameras[0].source->loop);
  expectOneError("source: {file: front.mkv}\n",
                 "source: {file: front.mkv}\n      health: {frozen_check: never}\n",
                 {"rig.cameras[0].health.frozen_check: expected one of 'auto' 'on' 'off'"});
}

TEST_F(ConfigTest, CameraNamesAreIdentifiers) {
  expectOneError("name: front", "name: \"front cam\"",
                 {"name: expected letters, digits, '-' and '_', got 'front cam'"});
}

TEST_F(ConfigTest, DuplicateCameraNames) {
  expectOneError("- name: left", "- name: front",
                 {where(9, 13), "rig.cameras[1].name: duplicate camera name 'front'"});
}

TEST_F(ConfigTest, MissingRequiredKey) {
  expectOneError("fx_px: 300, ", "", {where(7, 13), "rig.cameras[0].lens: missing key 'fx_px'"});
}

TEST_F(ConfigTest, NotARotation) {
  expectOneError("yaw_deg: 90, pitch_deg: -40", "quaternion_wxyz: [1, 0.2, 0, 0]",
                 {"rig.cameras[1].mount.quaternion_wxyz: expected a unit quaternion (a rotation)"});
}

TEST_F(ConfigTest, WrongChoice) {
  expectOneError(
      "model: fisheye", "model: fishey",
      {"rig.cameras[1].lens.model: expected one of 'pinhole' 'fisheye' 'ocam'", "'fishey'"});
}

TEST_F(ConfigTest, OddFrameSize) {
  expectOneError("width_px: 640\n  height", "width_px: 641\n  height",
                 {"render.width_px: expected an even number, got 641"});
}

TEST_F(ConfigTest, TwoOutputsWriteOneFile) {
  expectOneError("{type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "{type: video, path: out/../out/mosaic.mp4}",
                 {where(21, 25), "outputs[1].path: two outputs write"});
}

TEST_F(ConfigTest, YamlSyntaxError) {
  expectOneError("  level: debug", "  level: [debug", {"config.yaml:", "not valid YAML"});
}

TEST_F(ConfigTest, EveryProblemIsReportedAtOnce) {
  std::string text(kGoodConfig);
  text.replace(text.find("sync_tolerance_ms: 5"), 20, "sync_tolerance_ms: -1");
  text.replace(text.find("{file: left.mkv}"), 16, "{file: gone.mkv}");
  text += "colour: {}\n";
  EXPECT_EQ(errorsOf(dir_.write("config.yaml", text)).size(), 3u);
}

TEST_F(ConfigTest, MissingConfigFile) {
  const auto messages = errorsOf(dir_ / "absent.yaml");
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_THAT(messages[0], HasSubstr((dir_ / "absent.yaml").string()));
  EXPECT_THAT(messages[0], HasSubstr("cannot open"));
}

TEST_F(ConfigTest, RigFileRoundTripsExactly) {
  const Config config = loadConfig(configWith("", ""));
  const auto rigFile = dir_ / "rig.yaml";
  writeRigFile(rigFile, config.cameras, "written by config_test");
  const auto cameras = loadRigFile(rigFile);
  ASSERT_EQ(cameras.size(), config.cameras.size());
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const auto& a = cameras[i].calibration;
    const auto& b = config.cameras[i].calibration;
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.role, b.role);
    EXPECT_EQ(a.intrinsics, b.intrinsics);
    EXPECT_EQ(a.pose.position, b.pose.position);
    EXPECT_LT(cv::norm(a.pose.rotation - b.pose.rotation, cv::NORM_INF), 1e-12);
    EXPECT_EQ(cameras[i].source->path, config.cameras[i].source->path);
  }
}

// The vehicle: one block that sizes the car model, the views and the bowl, in the config or in
// the rig file (the config's wins).
TEST_F(ConfigTest, TheVehicleSizesTheCarTheViewsAndTheBowl) {
  const Config car = loadConfig(dir_.write("config.yaml", std::string(kGoodConfig)));
  EXPECT_EQ(car.vehicle, std::nullopt);
  EXPECT_DOUBLE_EQ(car.render.car.lengthM, 4.5);
  const Config robot = loadConfig(dir_.write(
      "config.yaml",
      std::string(kGoodConfig) +
          "vehicle: {length_m: 0.5, width_m: 0.4, height_m: 0.3, ground_clearance_m: 0.05, "
          "front_overhang_m: 0.1, rear_overhang_m: 0.1, x_m: 0.1, margin_m: 0.05}\n"));
  ASSERT_TRUE(robot.vehicle.has_value());
  EXPECT_DOUBLE_EQ(robot.render.car.lengthM, 0.5);
  EXPECT_DOUBLE_EQ(robot.render.car.centreXM, 0.1);
  EXPECT_DOUBLE_EQ(robot.render.car.marginM, 0.05);
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

// The reference config shows every key at its default: loading it must give the code's defaults.
TEST(ReferenceConfig, DocumentsTheDefaults) {
  const testing::TempDir dir;
  std::filesystem::create_directories(dir / "config");
  std::filesystem::copy_file(
      std::filesystem::path(SURROUNDD_SOURCE_DIR) / "config/surroundd.reference.yaml",
      dir / "config/surroundd.reference.yaml");
  for (const auto* name : {"front", "right", "back", "left"}) {
    dir.write(std::string("recordings/demo/") + name + ".mkv", "");
  }
  const Config config = loadConfig(dir / "config/surroundd.reference.yaml");
  EXPECT_EQ(config.logLevel, spdlog::level::info);
  EXPECT_EQ(config.cameras.size(), 4u);
  EXPECT_EQ(config.cameras[0].frozenCheck, FrozenCheck::kAuto);
  EXPECT_EQ(config.capture, CaptureConfig{});
  EXPECT_EQ(config.pipeline, PipelineConfig{});
  EXPECT_EQ(config.panorama, PanoramaConfig{});
  EXPECT_EQ(config.colour, ColourCorrectionConfig{});
  // Sizes that follow the vehicle are commented out there: a config without those sections.
  std::ifstream file(dir / "config/surroundd.reference.yaml");
  const std::string text{std::istreambuf_iterator<char>(file), {}};
  const auto section = [&](std::string_view key) {
    const auto first = text.find(std::string("\n") + std::string(key) + ":");
    const auto next = text.find("\n\n", first + 1);
    return std::pair{first + 1, next};
  };
  std::string bare = text;
  for (const auto* key : {"render", "mesh"}) {
    const auto [first, next] = section(key);
    bare.erase(bare.find(text.substr(first, next - first)), next - first);
  }
  const Config defaults = loadConfig(dir.write("config/bare.yaml", bare));
  EXPECT_EQ(config.mesh, defaults.mesh);
  EXPECT_EQ(config.render, defaults.render);
  EXPECT_EQ(config.vehicle, std::nullopt);
  EXPECT_TRUE(config.warnings.empty()) << ::testing::PrintToString(config.warnings);
  EXPECT_EQ(config.control, ControlConfig{});
  ASSERT_EQ(config.outputs.size(), 2u);
  OutputConfig video;
  video.path = config.outputs[0].path;
  EXPECT_EQ(config.outputs[0], video);
  OutputConfig snapshot;
  snapshot.kind = OutputKind::kSnapshot;
  snapshot.path = config.outputs[1].path;
  EXPECT_EQ(config.outputs[1], snapshot);
}

}  // namespace
}  // namespace surroundd::daemon
