// Config validation: a good config loads to the expected values, and each class of mistake gives
// one message that names the file, line, column, key path and what was expected.

#include "daemon/config/config.hpp"

#include <fstream>
#include <string>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include "daemon/outputs/display/display_output.hpp"
#include "daemon/outputs/http/http_output.hpp"
#include "daemon/outputs/recording/recording_output.hpp"
#include "daemon/outputs/rtsp/rtsp_output.hpp"
#include "daemon/outputs/snapshot/snapshot_output.hpp"
#include "daemon/outputs/video/video_output.hpp"
#include "daemon/outputs/window/window_output.hpp"
#include "tests/daemon/config/config_test_support.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd::daemon {
namespace {

using ::testing::HasSubstr;

TEST_F(ConfigTest, GoodConfigLoads) {
  const Config config = loadConfig(configWith("", ""));
  EXPECT_EQ(config.logLevel, spdlog::level::debug);
  ASSERT_EQ(config.cameras.size(), 2u);
  const auto& front = config.cameras[0];
  EXPECT_EQ(front.calibration.name, "front");
  EXPECT_EQ(front.replayedFile()->path, dir_ / "front.mkv");  // relative to the config's folder
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
  EXPECT_EQ(settingsOf<VideoOutputSettings>(config.outputs[0]).h264.crf, 18);
  EXPECT_EQ(config.outputs[1].kind, OutputKind::kSnapshot);
  EXPECT_DOUBLE_EQ(settingsOf<SnapshotOutputSettings>(config.outputs[1]).atSeconds, 0.5);
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

// The balance's reference names one of the rig's cameras, and is the balance's only.
TEST_F(ConfigTest, TheBalanceReferenceIsACameraOfTheBalance) {
  const auto with = [&](std::string_view colour) {
    return dir_.write("config.yaml", std::string(kGoodConfig) +
                                         "colour_correction: " + std::string(colour) + "\n");
  };
  EXPECT_EQ(
      loadConfig(with("{balance: true, balance_reference: left}")).colour.poisson.balanceReference,
      "left");
  EXPECT_EQ(loadConfig(with("{balance: true}")).colour.poisson.balanceReference, "");
  const auto roof = errorsOf(with("{balance: true, balance_reference: roof}"));
  ASSERT_EQ(roof.size(), 1u) << ::testing::PrintToString(roof);
  EXPECT_THAT(roof[0], HasSubstr("colour_correction.balance_reference: no camera is named 'roof'"));
  const auto alone = errorsOf(with("{balance_reference: left}"));
  ASSERT_EQ(alone.size(), 1u) << ::testing::PrintToString(alone);
  EXPECT_THAT(alone[0], HasSubstr("colour_correction.balance_reference: is the balance's: it needs "
                                  "balance: true"));
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
  EXPECT_TRUE(left.live());
  EXPECT_EQ(left.replayedFile(), nullptr);
  ASSERT_NE(left.v4l2(), nullptr);
  EXPECT_EQ(left.v4l2()->device, "/dev/v4l/by-path/pci-0000:00:14.0-usb-0:1:1.0-video-index0");
  EXPECT_EQ(left.v4l2()->format, capture::V4l2Format::kMjpeg);
  EXPECT_EQ(left.v4l2()->size, cv::Size(640, 360));
  EXPECT_DOUBLE_EQ(left.v4l2()->fps, 25.0);
  EXPECT_EQ(left.v4l2()->timeout, std::chrono::milliseconds(300));
  EXPECT_EQ(left.v4l2()->controls,
            (std::vector<capture::V4l2Control>{{"exposure_auto", 1}, {"gain", 40}}));

  // And back through a rig file.
  writeRigFile(dir_ / "rig.yaml", config.cameras, "test");
  const auto cameras = loadRigFile(dir_ / "rig.yaml");
  ASSERT_NE(cameras[1].v4l2(), nullptr);
  EXPECT_EQ(*cameras[1].v4l2(), *left.v4l2());
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
  ASSERT_TRUE(left.source.has_value());
  const auto* libcamera = std::get_if<capture::LibcameraSettings>(&*left.source);
  ASSERT_NE(libcamera, nullptr);
  EXPECT_EQ(libcamera->camera, "imx219@10");
  EXPECT_EQ(libcamera->size, cv::Size(640, 360));
  EXPECT_DOUBLE_EQ(libcamera->fps, 25.0);
  writeRigFile(dir_ / "rig.yaml", config.cameras, "test");
  EXPECT_EQ(loadRigFile(dir_ / "rig.yaml")[1].source, left.source);
}

TEST_F(ConfigTest, ARecordingIsAFolder) {
  const Config config =
      loadConfig(configWith("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                            "  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}\n"
                            "  - {type: recording, path: out/drive, lossless: false, crf: 20}"));
  ASSERT_EQ(config.outputs.size(), 3u);
  EXPECT_EQ(config.outputs[2].kind, OutputKind::kRecording);
  EXPECT_EQ(config.outputs[2].path, dir_ / "out/drive");
  EXPECT_FALSE(settingsOf<RecordingOutputSettings>(config.outputs[2]).lossless);
  EXPECT_EQ(settingsOf<RecordingOutputSettings>(config.outputs[2]).h264.crf, 20);
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
  EXPECT_DOUBLE_EQ(settingsOf<VideoOutputSettings>(config.outputs[1]).segmentS, 60.0);
  EXPECT_EQ(config.outputs[2].kind, OutputKind::kNetwork);
  EXPECT_EQ(settingsOf<NetworkOutputSettings>(config.outputs[2]).url, "udp://239.0.0.1:5600");
  EXPECT_EQ(settingsOf<NetworkOutputSettings>(config.outputs[2]).h264.crf, 28);
  EXPECT_EQ(settingsOf<VideoOutputSettings>(config.outputs[1]).h264.encoder, "auto");
  EXPECT_TRUE(config.outputs[2].path.empty());
  // The H.264 encoder by name: one this FFmpeg has, and H.264.
  EXPECT_EQ(settingsOf<VideoOutputSettings>(
                loadConfig(configWith("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                                      "  - {type: video, path: out/a.mp4, encoder: libx264}"))
                    .outputs[1])
                .h264.encoder,
            "libx264");
  expectOneError("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: video, path: out/a.mp4, encoder: h264_warp}",
                 {"outputs[1].encoder: this FFmpeg has no encoder 'h264_warp'"});
  expectOneError("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: network, url: \"udp://127.0.0.1:5600\", encoder: mjpeg}",
                 {"outputs[1].encoder: 'mjpeg' does not encode H.264"});
  EXPECT_EQ(config.control.socket, dir_ / "run/control.sock");
  // Beyond this machine only with a password file (issue 50), read as the config is.
  dir_.write("viewers.pw", "driver:correct horse battery\n");
  std::filesystem::permissions(dir_ / "viewers.pw", std::filesystem::perms::owner_read |
                                                        std::filesystem::perms::owner_write);
  const Config pages = loadConfig(
      configWith("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: http, stream: surround, listen: \"0.0.0.0:9000\", quality: 60,\n"
                 "     password_file: viewers.pw}\n"
                 "  - {type: window, display: \":3\", title: rig}\n"
                 "  - {type: http, stream: mosaic}\n"
                 "  - {type: display, stream: surround, device: /dev/dri/card1, "
                 "connector: HDMI-A-1}\n"
                 "  - {type: rtsp, stream: surround}\n"
                 "  - {type: rtsp, stream: mosaic, listen: \"0.0.0.0:9554\", name: cameras, "
                 "crf: 30, password_file: viewers.pw}"));
  ASSERT_EQ(pages.outputs.size(), 7u);
  EXPECT_EQ(pages.outputs[1].kind, OutputKind::kHttp);
  EXPECT_EQ(settingsOf<HttpOutputSettings>(pages.outputs[1]).server.address, "0.0.0.0");
  EXPECT_EQ(settingsOf<HttpOutputSettings>(pages.outputs[1]).server.port, 9000);
  EXPECT_EQ(settingsOf<HttpOutputSettings>(pages.outputs[1]).jpegQuality, 60);
  ASSERT_TRUE(settingsOf<HttpOutputSettings>(pages.outputs[1]).server.credentials.has_value());
  EXPECT_EQ(settingsOf<HttpOutputSettings>(pages.outputs[1]).server.credentials->user, "driver");
  EXPECT_EQ(settingsOf<HttpOutputSettings>(pages.outputs[1]).server.credentials->password,
            "correct horse battery");
  EXPECT_EQ(settingsOf<RtspOutputSettings>(pages.outputs[6]).server.credentials,
            settingsOf<HttpOutputSettings>(pages.outputs[1]).server.credentials);
  EXPECT_FALSE(settingsOf<HttpOutputSettings>(pages.outputs[3])
                   .server.credentials.has_value());  // 127.0.0.1: none asked
  expectOneError("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: http, listen: \"0.0.0.0:9000\"}",
                 {"outputs[1].listen: listens on 0.0.0.0, beyond this machine, and no "
                  "password_file says who may watch"});
  expectOneError("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: rtsp, listen: \"192.168.1.5:8554\"}",
                 {"outputs[1].listen: listens on 192.168.1.5, beyond this machine"});
  std::filesystem::permissions(dir_ / "viewers.pw", std::filesystem::perms::group_read,
                               std::filesystem::perm_options::add);
  expectOneError("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: http, listen: \"0.0.0.0:9000\", password_file: viewers.pw}",
                 {"outputs[1].password_file: ",
                  "viewers.pw: others than its owner may read or "
                  "change it (mode 640): chmod 600 it"});
  EXPECT_EQ(pages.outputs[2].kind, OutputKind::kWindow);
  EXPECT_EQ(settingsOf<WindowOutputSettings>(pages.outputs[2]).display, ":3");
  EXPECT_EQ(settingsOf<WindowOutputSettings>(pages.outputs[2]).title, "rig");
  EXPECT_EQ(settingsOf<HttpOutputSettings>(pages.outputs[3]).server.address,
            "127.0.0.1");  // only this machine by default
  EXPECT_EQ(settingsOf<HttpOutputSettings>(pages.outputs[3]).server.port, 8080);
  EXPECT_EQ(pages.outputs[4].kind, OutputKind::kDisplay);
  EXPECT_EQ(settingsOf<DisplayOutputSettings>(pages.outputs[4]).device, "/dev/dri/card1");
  EXPECT_EQ(settingsOf<DisplayOutputSettings>(pages.outputs[4]).connector, "HDMI-A-1");
  EXPECT_EQ(pages.outputs[5].kind, OutputKind::kRtsp);
  EXPECT_EQ(settingsOf<RtspOutputSettings>(pages.outputs[5]).server.address, "127.0.0.1");
  EXPECT_EQ(settingsOf<RtspOutputSettings>(pages.outputs[5]).server.port,
            8554);  // RTSP's own port by default
  EXPECT_EQ(settingsOf<RtspOutputSettings>(pages.outputs[5]).name, "");  // named by what it shows
  EXPECT_EQ(settingsOf<RtspOutputSettings>(pages.outputs[6]).server.address, "0.0.0.0");
  EXPECT_EQ(settingsOf<RtspOutputSettings>(pages.outputs[6]).server.port, 9554);
  EXPECT_EQ(settingsOf<RtspOutputSettings>(pages.outputs[6]).name, "cameras");
  EXPECT_EQ(settingsOf<RtspOutputSettings>(pages.outputs[6]).h264.crf, 30);
  expectOneError(
      "  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
      "  - {type: http, listen: \"localhost\"}",
      {"outputs[1].listen: expected IPv4-ADDRESS:PORT (e.g. 127.0.0.1:8080), got 'localhost'"});
  expectOneError("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: http, listen: \"localhost:8080\"}", {"got 'localhost:8080'"});
  expectOneError("  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}",
                 "  - {type: rtsp, listen: \"127.0.0.1:8554\", name: \"rear view\"}",
                 {"outputs[1].name: expected letters, digits, '-', '_' and '.', got 'rear view'"});
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

// A file name reaches no printf-family call (issue 18: "%s%s%s" crashed --check-config, a
// "%999999999d" took 16 s): only one %d or %0Nd makes a sequence pattern.
TEST_F(ConfigTest, PercentsInAFileNameAreNeverFormatted) {
  for (const char* name : {"x%s%s%s%s%s%s%s%s.png", "x%n%n%n.png", "x%d%s.png"}) {
    expectOneError(
        "{file: left.mkv}", fmt::format("{{file: \"{}\"}}", name),
        {"rig.cameras[1].source.file: expected an existing video file or picture", "no such file"});
  }
  expectOneError("{file: left.mkv}", "{file: x%999999999d.png}",
                 {"rig.cameras[1].source.file: expected an image sequence pattern with %d or "
                  "%0Nd (N up to 32)",
                  "its number is wider than that"});
  dir_.write("x%s%n.png", "");
  EXPECT_NO_THROW(loadConfig(configWith("{file: left.mkv}", "{file: \"x%s%n.png\"}")));
}

// A still picture loops unless told not to, at sequence_fps; the frozen check is set per camera.
TEST_F(ConfigTest, StillPicturesLoopAndTheFrozenCheckIsPerCamera) {
  dir_.write("front.png", "");
  const Config config = loadConfig(configWith(
      "source: {file: front.mkv}\n",
      "source: {file: front.png, sequence_fps: 10}\n      health: {frozen_check: on}\n"));
  ASSERT_TRUE(config.cameras[0].source.has_value());
  EXPECT_TRUE(config.cameras[0].replayedFile()->loop);
  EXPECT_EQ(config.cameras[0].replayedFile()->sequenceFps, 10.0);
  EXPECT_EQ(config.cameras[0].frozenCheck, FrozenCheck::kOn);
  EXPECT_FALSE(config.cameras[1].replayedFile()->loop);  // a video plays once by default
  EXPECT_EQ(config.cameras[1].frozenCheck, FrozenCheck::kAuto);

  const Config once =
      loadConfig(configWith("source: {file: front.mkv}", "source: {file: front.png, loop: false}"));
  EXPECT_FALSE(once.cameras[0].replayedFile()->loop);
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

// A config (or rig) path that is no file is named and refused; a FIFO does not block the reader.
TEST_F(ConfigTest, AConfigThatIsNoFileIsRefusedUnread) {
  std::filesystem::create_directory(dir_ / "folder.yaml");
  ASSERT_EQ(::mkfifo((dir_ / "fifo.yaml").c_str(), 0600), 0);
  for (const auto& [name, kind] : {std::pair{"folder.yaml", "a directory, not a file"},
                                   std::pair{"fifo.yaml", "a FIFO, not a file"}}) {
    const auto messages = errorsOf(dir_ / name);
    ASSERT_EQ(messages.size(), 1u);
    EXPECT_THAT(messages[0], AllOf(HasSubstr((dir_ / name).string()), HasSubstr(kind)));
  }
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
    EXPECT_EQ(cameras[i].replayedFile()->path, config.cameras[i].replayedFile()->path);
  }
  // Where the cameras came from: none written inline, the rig file where one is named.
  EXPECT_FALSE(config.rigFile.has_value());
  std::ofstream(dir_ / "from-rig.yaml") << "rig: {file: rig.yaml}\n"
                                        << "outputs:\n  - {type: snapshot, stream: mosaic, path: "
                                           "s.png}\n";
  const Config fromRig = loadConfig(dir_ / "from-rig.yaml");
  ASSERT_TRUE(fromRig.rigFile.has_value());
  EXPECT_TRUE(std::filesystem::equivalent(*fromRig.rigFile, rigFile));
  EXPECT_EQ(fromRig.cameras.size(), config.cameras.size());
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
  video.settings = OutputSettings(VideoOutputSettings{});
  EXPECT_EQ(config.outputs[0], video);
  OutputConfig snapshot;
  snapshot.kind = OutputKind::kSnapshot;
  snapshot.path = config.outputs[1].path;
  snapshot.settings = OutputSettings(SnapshotOutputSettings{});
  EXPECT_EQ(config.outputs[1], snapshot);
}

}  // namespace
}  // namespace surroundd::daemon
