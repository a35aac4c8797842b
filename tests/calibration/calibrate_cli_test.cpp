// surround-calibrate as a user runs it: images and YAML files in, lens: and mount: blocks that the
// rig reader accepts out, within the accuracy asked of calibration; and for every kind of bad input
// a non-zero exit and one message that names the file or option and what was wrong.

#include <array>
#include <fstream>
#include <numbers>
#include <sstream>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "tests/calibration/calibrate_run.hpp"
#include "tests/calibration/calibration_test_support.hpp"
#include "tests/support/child_process.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::calibration::testing {
namespace {

using surroundd::testing::TempDir;
using ::testing::HasSubstr;
using ::testing::Not;

const processing::Checkerboard kBoard{{9, 6}, 0.05};

std::filesystem::path writeImages(const TempDir& dir, const std::string& folder,
                                  const std::vector<cv::Mat>& images) {
  auto path = dir / folder;
  std::filesystem::create_directories(path);
  for (std::size_t i = 0; i < images.size(); ++i) {
    cv::imwrite((path / fmt::format("view_{:02}.png", i)).string(), images[i]);
  }
  return path;
}

constexpr std::string_view kRigHeader =
    "# The test car's rig, measured by hand on 2024-05-02.\n#   (kept by --update-rig)\n\n";

// A rig file as a user keeps one before calibration: a header comment, the camera with a still
// picture as its source at a rate of its own, its colour role and health settings, and a second
// camera. --update-rig must keep all of it but the block it replaces.
std::filesystem::path writeRig(const TempDir& dir, const processing::CameraCalibration& camera) {
  std::array<daemon::RigCamera, 2> entries;
  entries[0].calibration = camera;
  entries[1].calibration = camera;
  entries[1].calibration.name = "spare";
  entries[1].calibration.pose.position[0] += 1.25;
  auto file = dir / "rig.yaml";
  daemon::writeRigFile(file, entries, "");
  cv::imwrite((dir / "still.png").string(),
              cv::Mat(camera.intrinsics.imageSize, CV_8UC3, cv::Scalar::all(128)));
  YAML::Node rig = YAML::LoadFile(file.string());
  rig["cameras"][0]["source"] = YAML::Load("{file: still.png, sequence_fps: 12.5}");
  rig["cameras"][0]["role"] = "target";
  rig["cameras"][0]["health"] = YAML::Load("{frozen_check: off}");
  YAML::Emitter out;
  out << rig;
  std::ofstream(file) << kRigHeader << out.c_str() << "\n";
  return file;
}

// What --update-rig must have kept of the rig writeRig wrote (`before`, as it read then).
void expectRigKept(const std::filesystem::path& rig, const std::vector<daemon::RigCamera>& before) {
  const std::string text = surroundd::testing::fileBytes(rig);
  EXPECT_TRUE(text.starts_with(kRigHeader)) << text;
  EXPECT_THAT(text, HasSubstr("# Written by surround-calibrate"));
  EXPECT_FALSE(std::filesystem::exists(rig.string() + ".part"));
  const auto after = daemon::loadRigFile(rig);
  ASSERT_EQ(after.size(), 2u);
  ASSERT_TRUE(after[0].source.has_value());
  EXPECT_EQ(after[0].replayedFile()->path.filename(), "still.png");
  EXPECT_EQ(after[0].replayedFile()->sequenceFps, 12.5);
  EXPECT_TRUE(after[0].replayedFile()->loop);
  EXPECT_EQ(after[0].frozenCheck, daemon::FrozenCheck::kOff);
  EXPECT_EQ(after[0].calibration.role, processing::ColourRole::kTarget);
  // The other camera, value for value.
  EXPECT_EQ(after[1].calibration.name, "spare");
  EXPECT_EQ(after[1].calibration.intrinsics, before[1].calibration.intrinsics);
  EXPECT_EQ(after[1].calibration.pose.position, before[1].calibration.pose.position);
  EXPECT_EQ(after[1].calibration.pose.rotation, before[1].calibration.pose.rotation);
}

std::string markerYaml(const processing::MarkerLayout& layout) {
  std::string text = "aruco_dictionary: 4x4_50\nmarkers:\n";
  for (const auto& m : layout.markers) {
    const auto common = fmt::format("name: {}, x_m: {:.17g}, y_m: {:.17g}, yaw_deg: {:.17g}",
                                    m.name, m.centre[0], m.centre[1], m.yawDeg);
    text +=
        m.kind == processing::MarkerKind::kAruco
            ? fmt::format("  - {{{}, type: aruco, id: {}, side_m: {}}}\n", common, m.arucoId,
                          m.arucoSideM)
            : fmt::format("  - {{{}, type: checkerboard, inner_corners: [{}, {}], square_m: {}}}\n",
                          common, m.board.innerCorners.width, m.board.innerCorners.height,
                          m.board.squareM);
  }
  return text;
}

// A block written by surround-calibrate, read back through the rig reader inside a camera.
processing::CameraCalibration readBack(const TempDir& dir, const std::string& lensBlock,
                                       const std::string& mountBlock) {
  const auto indent = [](const std::string& block) {
    std::string out;
    std::istringstream lines(block);
    for (std::string line; std::getline(lines, line);) out += "    " + line + "\n";
    return out;
  };
  const auto file = dir.write("readback.yaml",
                              "cameras:\n  - name: c\n" + indent(lensBlock) + indent(mountBlock));
  return daemon::loadRigFile(file).front().calibration;
}

const std::string kPinholeLens =
    "lens: {model: pinhole, width_px: 640, height_px: 360, fx_px: 268.5, fy_px: 268.5, cx_px: "
    "319.5, cy_px: 179.5, distortion: [0, 0, 0, 0, 0]}\n";
const std::string kZeroMount = "mount: {x_m: 0, y_m: 0, z_m: 0}\n";

TEST(CalibrateCli, IntrinsicsWriteALensBlockTheRigAccepts) {
  const TempDir dir;
  const auto camera = presetCameras("fisheye.yaml").front();
  const auto& truth = camera.intrinsics;
  const auto images = writeImages(dir, "views", boardViews(truth, kBoard, 12, 8));
  const auto rig = writeRig(dir, camera);
  const auto before = daemon::loadRigFile(rig);
  const CalibrateRun run = calibrate(
      dir, {"intrinsics", "--images", images.string(), "--board", "9x6", "--model", "fisheye",
            "--out", (dir / "lens.yaml").string(), "--residuals", (dir / "residuals.png").string(),
            "--update-rig", rig.string(), "--camera", camera.name});
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("[ 12/12]"));
  EXPECT_THAT(run.output, HasSubstr("verdict: PASS"));
  EXPECT_THAT(run.output, HasSubstr("view_00.png"));
  EXPECT_THAT(run.output, HasSubstr("RMS 0.0"));
  const auto lens =
      readBack(dir, surroundd::testing::fileBytes(dir / "lens.yaml"), kZeroMount).intrinsics;
  EXPECT_EQ(lens.model, processing::LensModel::kFisheye);
  EXPECT_EQ(lens.imageSize, truth.imageSize);
  EXPECT_NEAR(lens.fx / truth.fx, 1, 0.005);
  EXPECT_NEAR(lens.fy / truth.fy, 1, 0.005);
  // A few degrees past the widest angle the board's corners reached (issue 47: the polynomial
  // is known only where corners were): about 68 degrees off the axis in these views, so about 146
  // of the lens's 190, and the output says why.
  const double fieldDeg = lens.maxFieldAngleRad * 360 / std::numbers::pi;
  EXPECT_GT(fieldDeg, 120);
  EXPECT_LT(fieldDeg, 185);
  EXPECT_THAT(run.output, HasSubstr(fmt::format(
                              "limited to {:.1f} deg: the board's corners reached", fieldDeg)));
  EXPECT_FALSE(cv::imread((dir / "residuals.png").string()).empty());
  // --update-rig: the rig's camera has the new lens and keeps its mount, and the rig keeps every
  // other key.
  const auto updated = daemon::loadRigFile(rig).front().calibration;
  EXPECT_NEAR(updated.intrinsics.fx, lens.fx, 1e-6);
  EXPECT_NEAR(updated.intrinsics.maxFieldAngleRad, lens.maxFieldAngleRad, 1e-9);
  EXPECT_LT(poseError(updated.pose, camera.pose).positionCm, 1e-9);
  expectRigKept(rig, before);
}

TEST(CalibrateCli, ExtrinsicsWriteAMountBlockTheRigAccepts) {
  const TempDir dir;
  auto camera = presetCameras("paper.yaml", kGroundViewSize).front();
  const auto layout = synth::groundMarkersInView(camera, groundMarkers(0.2, 0.4));
  cv::imwrite((dir / "front.png").string(), groundView(camera, layout, 3));
  const auto markers = dir.write("markers.yaml", markerYaml(layout));
  const processing::Pose truth = camera.pose;
  camera.pose = nominal(truth);
  const auto rig = writeRig(dir, camera);
  const auto before = daemon::loadRigFile(rig);
  const CalibrateRun run =
      calibrate(dir, {"extrinsics", "--rig", rig.string(), "--camera", "front", "--image",
                      (dir / "front.png").string(), "--markers", markers.string(), "--out",
                      (dir / "mount.yaml").string(), "--residuals",
                      (dir / "residuals.png").string(), "--update-rig"});
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr(fmt::format("found {} of {} markers", layout.markers.size(),
                                                layout.markers.size())));
  EXPECT_THAT(run.output, HasSubstr("change from the rig"));
  const auto pose =
      readBack(dir, kPinholeLens, surroundd::testing::fileBytes(dir / "mount.yaml")).pose;
  const PoseError error = poseError(pose, truth);
  EXPECT_LT(error.positionCm, 1.0);
  EXPECT_LT(error.rotationDeg, 0.2);
  EXPECT_FALSE(cv::imread((dir / "residuals.png").string()).empty());
  const auto updated = daemon::loadRigFile(rig).front().calibration;
  EXPECT_LT(poseError(updated.pose, pose).positionCm, 1e-6);
  EXPECT_LT(poseError(updated.pose, pose).rotationDeg, 1e-6);
  EXPECT_EQ(updated.intrinsics, before[0].calibration.intrinsics);  // the lens as it was
  expectRigKept(rig, before);
}

// Bad input: one line on stderr that names the file or option, and the exit status says whose
// problem it is (2: what was passed; 1: the images did not hold enough).
void expectFailure(const CalibrateRun& run, int status, const std::string& message) {
  EXPECT_EQ(run.status, status) << run.output;
  EXPECT_THAT(run.output, HasSubstr(message));
}

std::vector<std::string> intrinsicsOn(const TempDir& dir, const std::filesystem::path& images) {
  return {"intrinsics", "--images", images.string(),
          "--board",    "9x6",      "--model",
          "pinhole",    "--out",    (dir / "lens.yaml").string()};
}

TEST(CalibrateCli, IntrinsicsOfAnEmptyOrMissingFolder) {
  const TempDir dir;
  std::filesystem::create_directories(dir / "empty");
  dir.write("empty/notes.txt", "not an image");
  expectFailure(
      calibrate(dir, intrinsicsOn(dir, dir / "empty")), 2,
      "surround-calibrate intrinsics: --images: '" + (dir / "empty").string() +
          "' holds no images (looked for .png .jpg .jpeg .bmp .tif .tiff .pgm .ppm .pnm)");
  expectFailure(calibrate(dir, intrinsicsOn(dir, dir / "missing")), 2,
                "--images: '" + (dir / "missing").string() + "' is not a folder (no such folder)");
  EXPECT_FALSE(std::filesystem::exists(dir / "lens.yaml"));
}

TEST(CalibrateCli, IntrinsicsWithNoBoardInAnyImage) {
  const TempDir dir;
  const cv::Mat grey(360, 640, CV_8UC3, cv::Scalar(120, 120, 120));
  const auto images = writeImages(dir, "views", {grey, grey, grey});
  expectFailure(calibrate(dir, intrinsicsOn(dir, images)), 1,
                "surround-calibrate intrinsics: calibration failed: no 9x6 chessboard found in "
                "any of the 3 images in '" +
                    images.string() + "' (--board counts inner corners");
}

TEST(CalibrateCli, IntrinsicsWithTooFewViews) {
  const TempDir dir;
  const auto truth = presetCameras("paper.yaml").front().intrinsics;
  auto views = boardViews(truth, kBoard, 3, 2);
  views.emplace_back(360, 640, CV_8UC3, cv::Scalar(120, 120, 120));
  const auto images = writeImages(dir, "views", views);
  expectFailure(calibrate(dir, intrinsicsOn(dir, images)), 1,
                "calibration failed: too few views: 3 usable (found in view_00.png, view_01.png, "
                "view_02.png), at least 5 are needed (from different angles and field positions); "
                "skipped: view_03.png: no board");
}

TEST(CalibrateCli, IntrinsicsWithAnUnreadableOrOddSizedImage) {
  const TempDir dir;
  const cv::Mat grey(360, 640, CV_8UC3, cv::Scalar(120, 120, 120));
  const auto images = writeImages(dir, "views", {grey, grey});
  dir.write("views/view_01b.png", "PNG? no: a text file with the wrong name");
  expectFailure(
      calibrate(dir, intrinsicsOn(dir, images)), 2,
      (images / "view_01b.png").string() + ": cannot read the image (not an image, or damaged)");
  std::filesystem::remove(images / "view_01b.png");
  cv::imwrite((images / "view_02.png").string(), cv::Mat(180, 320, CV_8UC3, cv::Scalar(0)));
  expectFailure(calibrate(dir, intrinsicsOn(dir, images)), 2,
                (images / "view_02.png").string() +
                    ": the image is 320x180, the others are 640x360; the images must all come "
                    "from one camera at one resolution");
}

// Issue 47: a lens fitted to 640x480 pictures was written over a 1920x1280 camera's without a
// word. Pictures of another size than the camera's are refused, naming both, before the solve,
// and the rig is left as it was.
TEST(CalibrateCli, IntrinsicsForARigCameraOfAnotherSizeAreRefused) {
  const TempDir dir;
  auto camera = presetCameras("paper.yaml").front();
  const auto images = writeImages(dir, "views", boardViews(camera.intrinsics, kBoard, 6, 5));
  const cv::Size pictures = camera.intrinsics.imageSize;
  camera.intrinsics.imageSize = pictures * 2;
  camera.intrinsics.cx = 2 * camera.intrinsics.cx;
  camera.intrinsics.cy = 2 * camera.intrinsics.cy;
  const auto rig = writeRig(dir, camera);
  const std::string before = surroundd::testing::fileBytes(rig);
  auto arguments = intrinsicsOn(dir, images);
  arguments.insert(arguments.end(), {"--update-rig", rig.string(), "--camera", camera.name});
  expectFailure(calibrate(dir, arguments), 2,
                fmt::format("--update-rig: camera '{}' in {} takes {}x{} pictures, these are {}x{}",
                            camera.name, rig.string(), 2 * pictures.width, 2 * pictures.height,
                            pictures.width, pictures.height));
  EXPECT_EQ(surroundd::testing::fileBytes(rig), before);
  EXPECT_FALSE(std::filesystem::exists(dir / "lens.yaml"));
}

// The guide's camera: an unreachable device, a recording that is not there (needs the guide's
// page: a build without HTTP refuses the guide before it opens a camera).
TEST(CalibrateCli, GuideCamerasThatCannotBeOpenedAreNamed) {
  const TempDir dir;
  const std::vector<std::string> guide{
      "guide", "--board", "9x6", "--model", "fisheye", "--out", (dir / "lens.yaml").string()};
  auto onDevice = guide;
  onDevice.insert(onDevice.end(), {"--device", (dir / "video9").string()});
  expectFailure(calibrate(dir, onDevice), 2,
                "surround-calibrate guide: --device: camera 'guide': " + (dir / "video9").string() +
                    ": cannot open: No such file or directory");
  auto onFile = guide;
  onFile.insert(onFile.end(), {"--file", (dir / "missing_%04d.png").string()});
  expectFailure(calibrate(dir, onFile), 2, "surround-calibrate guide: --file: ");
  EXPECT_FALSE(std::filesystem::exists(dir / "lens.yaml"));
}

// A build without HTTP has no guide page: asking for it is refused before any camera is opened,
// with how to build it in.
TEST(CalibrateCli, GuideInABuildWithoutItsPageSaysHowToBuildIt) {
  if (SURROUNDD_GUIDE_BUILT) GTEST_SKIP() << "this build has the guide (SURROUNDD_WITH_HTTP on)";
  const TempDir dir;
  const CalibrateRun run =
      calibrate(dir, {"guide", "--board", "9x6", "--model", "fisheye", "--device",
                      (dir / "video9").string(), "--out", (dir / "lens.yaml").string()});
  expectFailure(run, 2,
                "surround-calibrate guide: this build has no HTTP server for its page (configure "
                "with -DSURROUNDD_WITH_HTTP=ON");
  EXPECT_THAT(run.output, Not(HasSubstr("cannot open")));
  EXPECT_THAT(run.output, Not(HasSubstr("failed")));
}

// Issue 50: a guide's page served beyond this machine asks who may see it, as the daemon's do.
TEST(CalibrateCli, AGuidePageBeyondThisMachineNeedsAPasswordFile) {
  if (!SURROUNDD_GUIDE_BUILT) GTEST_SKIP() << "this build has no guide (SURROUNDD_WITH_HTTP off)";
  const TempDir dir;
  const std::vector<std::string> guide{"guide",
                                       "--board",
                                       "9x6",
                                       "--model",
                                       "fisheye",
                                       "--out",
                                       (dir / "lens.yaml").string(),
                                       "--file",
                                       (dir / "session_%04d.png").string(),
                                       "--listen",
                                       "0.0.0.0:0"};
  expectFailure(calibrate(dir, guide), 2,
                "surround-calibrate guide: --listen: 0.0.0.0 is beyond this machine: give "
                "--password-file FILE");
  const auto file = dir.write("viewers.pw", "driver:correct horse battery\n");
  std::filesystem::permissions(file, std::filesystem::perms::owner_read |
                                         std::filesystem::perms::owner_write |
                                         std::filesystem::perms::group_read);
  auto withFile = guide;
  withFile.insert(withFile.end(), {"--password-file", file.string()});
  expectFailure(calibrate(dir, withFile), 2,
                "surround-calibrate guide: --password-file: " + file.string() +
                    ": others than its owner may read or change it (mode 640): chmod 600 it");
}

TEST(CalibrateCli, UsageErrorsNameTheOption) {
  const TempDir dir;
  const CalibrateRun version = calibrate(dir, {"--version"});  // issue 50
  EXPECT_EQ(version.status, 0) << version.output;
  EXPECT_THAT(version.output, AllOf(HasSubstr("surround-calibrate 0."), HasSubstr("built with: ")));
  expectFailure(
      calibrate(dir, {}), 2,
      "surround-calibrate: missing the subcommand: intrinsics, guide, extrinsics, import, "
      "mask or refine (see --help)");
  expectFailure(calibrate(dir, {"calibrate"}), 2,
                "unknown subcommand 'calibrate': expected intrinsics, guide, extrinsics, import, "
                "mask or refine");
  // The guide without a camera (its other inputs: GuideCamerasThatCannotBeOpenedAreNamed).
  const std::vector<std::string> guide{
      "guide", "--board", "9x6", "--model", "fisheye", "--out", (dir / "lens.yaml").string()};
  expectFailure(calibrate(dir, guide), 2,
                "surround-calibrate guide: --device or --file: give one camera (a V4L2 device, or "
                "a recording)");
  EXPECT_FALSE(std::filesystem::exists(dir / "lens.yaml"));
  expectFailure(calibrate(dir, {"import", "--pjlab", dir.path().string(), "--axes",
                                "right,forward,down", "--out", "rig.yaml"}),
                2,
                "surround-calibrate import: --axes: 'right,forward,down' is a left-handed "
                "(mirrored) frame; a calibration's frame is right-handed, so one of the "
                "directions is wrong");
  auto arguments = intrinsicsOn(dir, dir.path());
  arguments[4] = "8x1";
  expectFailure(calibrate(dir, arguments), 2,
                "--board: expected COLSxROWS inner corners, each 2 to 64 (e.g. 9x6), got '8x1'");
  arguments = intrinsicsOn(dir, dir.path());
  arguments.insert(arguments.end(), {"--field-of-view-deg", "190"});
  expectFailure(calibrate(dir, arguments), 2, "--field-of-view-deg: only a fisheye lens takes it");
  arguments = intrinsicsOn(dir, dir.path());
  arguments.emplace_back("--update-rig");
  expectFailure(calibrate(dir, arguments), 2, "--update-rig: missing its value");
  arguments.emplace_back((dir / "rig.yaml").string());
  expectFailure(calibrate(dir, arguments), 2, "--update-rig and --camera go together");
  expectFailure(calibrate(dir, {"intrinsics", "--images", "x", "--model", "pinhole"}), 2,
                "--board: missing (a chessboard's inner corners, e.g. 9x6; or --charuco)");
  expectFailure(calibrate(dir, {"extrinsics", "--rig", "r.yaml", "--camera", "front", "--image",
                                "f.png", "--out", "m.yaml"}),
                2, "--markers or --points: missing");
  expectFailure(calibrate(dir, {"extrinsics", "--speed", "3"}), 2,
                "unknown option '--speed' (see --help)");
  const auto help = calibrate(dir, {"extrinsics", "--help"});
  EXPECT_EQ(help.status, 0);
  EXPECT_THAT(help.output, HasSubstr("usage: surround-calibrate extrinsics --rig FILE"));
  EXPECT_THAT(calibrate(dir, {"--help"}).output, HasSubstr("exit status: 0 done, 1 calibration"));
}

// The inputs of extrinsics: a rig with the camera, an image of its size, a valid marker file.
struct ExtrinsicsInputs {
  std::filesystem::path rig, image, markers;
};

ExtrinsicsInputs extrinsicsInputs(const TempDir& dir) {
  auto camera = presetCameras("paper.yaml").front();
  cv::imwrite((dir / "front.png").string(),
              cv::Mat(camera.intrinsics.imageSize, CV_8UC3, cv::Scalar(90, 90, 90)));
  return {writeRig(dir, camera), dir / "front.png",
          dir.write("markers.yaml",
                    "markers:\n  - {name: a, type: checkerboard, inner_corners: [5, 4], square_m: "
                    "0.2, x_m: 3, y_m: 0}\n")};
}

std::vector<std::string> extrinsicsOn(const TempDir& dir, const ExtrinsicsInputs& in,
                                      const std::string& camera = "front") {
  return {"extrinsics",
          "--rig",
          in.rig.string(),
          "--camera",
          camera,
          "--image",
          in.image.string(),
          "--markers",
          in.markers.string(),
          "--out",
          (dir / "mount.yaml").string()};
}

TEST(CalibrateCli, ExtrinsicsWithBadMarkerFilesNameTheLineAndKey) {
  const TempDir dir;
  auto in = extrinsicsInputs(dir);
  in.markers =
      dir.write("bad.yaml",
                "aruco_dictionary: 3x3_9\n"
                "markers:\n"
                "  - {name: a, type: checkerboard, inner_corners: [4, 4], square_m: 0.2, "
                "x_m: 3, y_m: 0}\n"
                "  - {name: a, type: aruco, id: 3, side_m: 0.3, x_m: 1, y_m: 1, yaw: 3}\n");
  const auto run = calibrate(dir, extrinsicsOn(dir, in));
  const std::string file = in.markers.string();
  expectFailure(run, 2, file + ":1:19: aruco_dictionary: expected one of 4x4_50, 4x4_100");
  EXPECT_THAT(run.output,
              HasSubstr(file + ":3:50: markers[0].inner_corners: expected [columns, "
                               "rows] of inner corners, each 2 to 64, one odd and one even"));
  EXPECT_THAT(run.output, HasSubstr("markers[1].name: duplicate marker name 'a'"));
  EXPECT_THAT(run.output, HasSubstr(file + ":4:64: markers[1].yaw: unknown key"));
}

TEST(CalibrateCli, ExtrinsicsWithTheWrongCameraOrImage) {
  const TempDir dir;
  const auto in = extrinsicsInputs(dir);
  expectFailure(
      calibrate(dir, extrinsicsOn(dir, in, "rear")), 2,
      "--camera: the rig '" + in.rig.string() + "' has no camera 'rear' (it has front, spare)");
  cv::imwrite(in.image.string(), cv::Mat(100, 100, CV_8UC3, cv::Scalar(0)));
  expectFailure(calibrate(dir, extrinsicsOn(dir, in)), 2,
                "--image: " + in.image.string() + " is 100x100, but camera 'front' in " +
                    in.rig.string() +
                    " has a 640x360 lens; calibrate the intrinsics at this resolution first");
  dir.write("front.png", "not a picture");
  expectFailure(calibrate(dir, extrinsicsOn(dir, in)), 2,
                "--image: " + in.image.string() + ": cannot read the image");
}

TEST(CalibrateCli, ExtrinsicsWhenNoMarkerIsInTheImage) {
  const TempDir dir;
  const auto in = extrinsicsInputs(dir);
  expectFailure(calibrate(dir, extrinsicsOn(dir, in)), 1,
                "surround-calibrate extrinsics: calibration failed: none of the 1 markers of " +
                    in.markers.string() + " was found in " + in.image.string());
  EXPECT_FALSE(std::filesystem::exists(dir / "mount.yaml"));
}

}  // namespace
}  // namespace surroundd::calibration::testing
