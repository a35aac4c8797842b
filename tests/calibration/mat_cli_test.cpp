// A mat session as a user runs it: surround-synth --calibration-mat lays a mat around the fisheye
// rig and takes one picture per camera, surround-calibrate extrinsics --mat solves every camera
// from a rig file a few centimetres and degrees off, and writes (and updates the rig) only when
// every camera and seam passed; every kind of bad input exits non-zero, says why, writes nothing.

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "tests/calibration/calibrate_run.hpp"
#include "tests/calibration/calibration_test_support.hpp"
#include "tests/support/test_support.hpp"
#include "tools/calibrate/marker_file.hpp"
#include "tools/synth/calibration_mat.hpp"

namespace surroundd::calibration::testing {
namespace {

using surroundd::testing::TempDir;
using ::testing::HasSubstr;
using ::testing::Not;

// The generator's session, once for all tests: DIR/NAME.png, mat.yaml, rig.yaml (the truth), and
// nominal.yaml, the rig as the user has it before calibration.
struct Session {
  TempDir dir;
  std::filesystem::path pictures = dir / "session";
  std::vector<daemon::RigCamera> truth;
};

const Session& session() {
  static const Session* made = [] {
    auto* s = new Session;
    surroundd::testing::ChildProcess synth(
        {SURROUND_SYNTH, "--rig", rigPreset("fisheye.yaml"), "--out", s->pictures.string(),
         "--size", "960x540", "--calibration-mat", "7x6@0.2"},
        s->dir / "synth.txt");
    EXPECT_EQ(synth.wait(), 0) << synth.output();
    s->truth = daemon::loadRigFile(s->pictures / "rig.yaml");
    return s;
  }();
  return *made;
}

// A folder of the test's own with the nominal rig and the session's pictures and mat.
std::filesystem::path nominalRig(const TempDir& dir) {
  auto cameras = session().truth;
  for (auto& camera : cameras) camera.calibration.pose = nominal(camera.calibration.pose);
  auto rig = dir / "rig.yaml";
  daemon::writeRigFile(rig, cameras, "The rig as measured by hand.");
  return rig;
}

std::vector<std::string> matArguments(const std::filesystem::path& rig,
                                      const std::filesystem::path& mat, const TempDir& dir) {
  return {"extrinsics",
          "--rig",
          rig.string(),
          "--mat",
          mat.string(),
          "--images",
          session().pictures.string(),
          "--out",
          (dir / "mounts.yaml").string()};
}

TEST(MatCli, EveryCameraOfTheFisheyeRigWrittenAndTheRigUpdated) {
  const TempDir dir;
  const auto rig = nominalRig(dir);
  auto arguments = matArguments(rig, session().pictures / "mat.yaml", dir);
  arguments.emplace_back("--update-rig");
  const CalibrateRun run = calibrate(dir, arguments);
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("camera      boards  corners   RMS px   moved cm  turn deg  "
                                    "verdict\nfront          2/2       84"));
  EXPECT_THAT(run.output, HasSubstr("  front|right      board front_right      RMS "));
  EXPECT_THAT(run.output, HasSubstr("updated 4 cameras in " + rig.string()));
  const YAML::Node written = YAML::LoadFile((dir / "mounts.yaml").string());
  const auto updated = daemon::loadRigFile(rig);
  ASSERT_EQ(written["cameras"].size(), 4u);
  for (std::size_t c = 0; c < 4; ++c) {
    const auto& truth = session().truth[c].calibration;
    SCOPED_TRACE(truth.name);
    const YAML::Node mount = written["cameras"][c]["mount"];
    EXPECT_EQ(written["cameras"][c]["name"].as<std::string>(), truth.name);
    processing::Pose pose;
    pose.position = {mount["x_m"].as<double>(), mount["y_m"].as<double>(),
                     mount["z_m"].as<double>()};
    pose.rotation = processing::rotationFromMountAngles({mount["yaw_deg"].as<double>(),
                                                         mount["pitch_deg"].as<double>(),
                                                         mount["roll_deg"].as<double>()});
    const PoseError error = poseError(pose, truth.pose);
    EXPECT_LT(error.positionCm, 1.0);
    EXPECT_LT(error.rotationDeg, 0.2);
    EXPECT_LT(poseError(updated[c].calibration.pose, pose).positionCm, 1e-6);
    EXPECT_EQ(updated[c].calibration.intrinsics, truth.intrinsics);
  }
}

// Refused: exit 1, the table says which camera and why, nothing written, the rig as it was.
void expectRefused(const TempDir& dir, const std::filesystem::path& rig,
                   std::vector<std::string> arguments, const std::string& problem) {
  const std::string before = surroundd::testing::fileBytes(rig);
  arguments.emplace_back("--update-rig");
  const CalibrateRun run = calibrate(dir, arguments);
  EXPECT_EQ(run.status, 1) << run.output;
  EXPECT_THAT(run.output, HasSubstr(problem));
  EXPECT_THAT(run.output, HasSubstr("(see the table above); nothing was written"));
  EXPECT_FALSE(std::filesystem::exists(dir / "mounts.yaml"));
  EXPECT_EQ(surroundd::testing::fileBytes(rig), before);
}

// The layout names a board that is not on the ground.
TEST(MatCli, ABoardMissingFromThePicturesIsRefused) {
  const TempDir dir;
  const auto rig = nominalRig(dir);
  const auto mat =
      dir.write("mat.yaml", surroundd::testing::fileBytes(session().pictures / "mat.yaml") +
                                "  - {name: spare, inner_corners: [7, 6], "
                                "square_m: 0.2, x_m: 4.5, y_m: 0, seen_by: [front]}\n");
  expectRefused(dir, rig, matArguments(rig, mat, dir), "front          2/3       84");
  const CalibrateRun run = calibrate(dir, matArguments(rig, mat, dir));
  EXPECT_THAT(run.output,
              HasSubstr("    problem: board 'spare': no 7x6 board within 0.6 m of its place in "
                        "the layout\n"));
  EXPECT_THAT(run.output, HasSubstr("surround-calibrate extrinsics: calibration failed: 1 of 4 "
                                    "cameras failed, 0 seam problems"));
}

TEST(MatCli, TooFewCornersAreRefused) {
  const TempDir dir;
  const auto rig = nominalRig(dir);
  auto arguments = matArguments(rig, session().pictures / "mat.yaml", dir);
  arguments.insert(arguments.end(), {"--min-corners", "100"});
  expectRefused(dir, rig, arguments, "    problem: too few corners: 84, at least 100 are needed");
}

// What the user passed is wrong: exit 2 and one line naming the file, key or option.
void expectBadInput(const TempDir& dir, const std::vector<std::string>& arguments,
                    const std::string& message) {
  const CalibrateRun run = calibrate(dir, arguments);
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr(message));
  EXPECT_FALSE(std::filesystem::exists(dir / "mounts.yaml"));
}

TEST(MatCli, AWrongLayoutFileIsNamedByFileLineAndKey) {
  const TempDir dir;
  const auto rig = nominalRig(dir);
  const auto mat = dir.write("mat.yaml",
                             "boards:\n"
                             "  - name: front_right\n"
                             "    inner_corners: [7, 6]\n"
                             "    square: 0.2\n"
                             "    x_m: 3.7\n"
                             "    y_m: -1.4\n"
                             "    seen_by: [front, right]\n"
                             "  - {name: front_right, inner_corners: [7, 1], square_m: 0.2, x_m: 1,"
                             " y_m: 2, seen_by: [left, left]}\n");
  const auto run = calibrate(dir, matArguments(rig, mat, dir));
  EXPECT_EQ(run.status, 2) << run.output;
  const std::string file = mat.string();
  EXPECT_THAT(run.output, HasSubstr(file + ":2:5: boards[0]: missing key 'square_m'"));
  EXPECT_THAT(run.output, HasSubstr(file + ":4:5: boards[0].square: unknown key"));
  EXPECT_THAT(run.output, HasSubstr("boards[1].inner_corners: expected [columns, rows] of inner "
                                    "corners, each 2 to 64 (e.g. [5, 4]), got [7, 1]"));
  EXPECT_THAT(run.output, HasSubstr("boards[1].seen_by: names camera 'left' twice"));
  EXPECT_THAT(run.output, HasSubstr("boards[1].name: duplicate board name 'front_right'"));
  EXPECT_FALSE(std::filesystem::exists(dir / "mounts.yaml"));

  const auto unknown = dir.write("unknown.yaml",
                                 "boards:\n  - {name: a, inner_corners: [7, 6], square_m: 0.2, "
                                 "x_m: 3.7, y_m: -1.4, seen_by: [front, rihgt]}\n");
  expectBadInput(dir, matArguments(rig, unknown, dir),
                 fmt::format("surround-calibrate extrinsics: {}: boards[0].seen_by: no camera "
                             "'rihgt' in {} (its cameras: front, right, back, left)",
                             unknown.string(), rig.string()));
}

TEST(MatCli, MissingPicturesAndOptionsThatDoNotGoTogether) {
  const TempDir dir;
  const auto rig = nominalRig(dir);
  std::filesystem::create_directories(dir / "three");
  for (const auto* camera : {"front", "right", "back"}) {
    std::filesystem::copy_file(session().pictures / (std::string(camera) + ".png"),
                               dir / "three" / (std::string(camera) + ".png"));
  }
  auto arguments = matArguments(rig, session().pictures / "mat.yaml", dir);
  arguments[6] = (dir / "three").string();
  expectBadInput(dir, arguments,
                 fmt::format("--images: {} holds no picture of camera 'left' (looked for "
                             "left.png, .jpg, .jpeg, .bmp, .tif, .tiff)",
                             (dir / "three").string()));
  arguments = matArguments(rig, session().pictures / "mat.yaml", dir);
  arguments.insert(arguments.end(), {"--camera", "front"});
  expectBadInput(dir, arguments,
                 "--mat: calibrates every camera the mat names from --images; --camera, --image, "
                 "--markers, --points and --residuals do not go with it");
}

// docs/calibration.md's example is the mat the generator lays around the fisheye preset, and reads back.
TEST(MatCli, TheExampleMatIsTheGeneratorsForTheFisheyeRig) {
  const auto example = calibrate::loadMatFile(std::string(SURROUNDD_SOURCE_DIR) +
                                              "/config/mats/four-corner-mat.yaml");
  const auto cameras = presetCameras("fisheye.yaml", {1280, 720});
  const auto laid = synth::groundMatAroundRig(cameras, {{{7, 6}, 0.2}, {}});
  ASSERT_EQ(example.boards.size(), laid.boards.size());
  for (std::size_t b = 0; b < laid.boards.size(); ++b) {
    const auto& a = example.boards[b];
    const auto& e = laid.boards[b];
    EXPECT_EQ(a.print.name, e.print.name);
    EXPECT_EQ(a.seenBy, e.seenBy);
    EXPECT_EQ(a.print.board.innerCorners, e.print.board.innerCorners);
    EXPECT_DOUBLE_EQ(a.print.board.squareM, e.print.board.squareM);
    EXPECT_NEAR(cv::norm(a.print.centre - e.print.centre), 0, 1e-9);
    EXPECT_DOUBLE_EQ(a.print.yawDeg, e.print.yawDeg);
  }
}

}  // namespace
}  // namespace surroundd::calibration::testing
