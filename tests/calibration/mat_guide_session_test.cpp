// The guided mat calibration (surround-calibrate guide --mat) over the generator's calibration
// mat around the fisheye rig: four cameras, a 7x6 board of 20 cm squares in each overlap, each
// camera's picture rendered from its true mount while the session starts from mounts a few
// centimetres and degrees off (synth::mountMeasuredByHand). A session solves once every camera
// has a picture; it must find every mount within 1 cm and 0.2 degrees, put every seam under the
// stated limit, stitch a top view, and write the mounts into the rig; a mat declared at the wrong
// size, or a camera that sees no board, must fail, say why, and leave the rig untouched.

#include "tools/calibrate/guide/mat_guide_session.hpp"

#include <algorithm>
#include <fstream>
#include <iterator>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "daemon/config/rig_yaml.hpp"
#include "processing/calibration/calibration_error.hpp"
#include "tests/calibration/mat_calibration_support.hpp"
#include "tests/support/temp_dir.hpp"
#include "tools/calibrate/extrinsics/mat_mounts_output.hpp"
#include "tools/calibrate/guide/mat_guide_state_json.hpp"
#include "tools/calibrate/guide/mat_guide_view.hpp"

namespace surroundd::calibration::testing {
namespace {

using ::testing::AllOf;
using ::testing::Contains;
using ::testing::HasSubstr;

const MatScene& fisheyeScene() {
  static const MatScene kScene = matScene("fisheye.yaml", {{{7, 6}, 0.2}, {}});
  return kScene;
}

calibrate::MatGuideSettings settingsFor(const MatScene& scene, const processing::MatLayout& mat) {
  calibrate::MatGuideSettings settings;
  settings.mat = mat;
  settings.cameras = scene.truth;
  for (auto& camera : settings.cameras) camera.pose = synth::mountMeasuredByHand(camera.pose);
  return settings;
}

// The rig as the user has it before calibrating, in a file the session's mounts can go into.
std::filesystem::path nominalRigFile(const surroundd::testing::TempDir& dir,
                                     const calibrate::MatGuideSettings& settings) {
  std::vector<daemon::RigCamera> cameras;
  for (const auto& calibration : settings.cameras) {
    daemon::RigCamera camera;
    camera.calibration = calibration;
    cameras.push_back(camera);
  }
  auto rig = dir / "rig.yaml";
  daemon::writeRigFile(rig, cameras, "The rig as measured by hand.");
  return rig;
}

std::string contents(const std::filesystem::path& file) {
  std::ifstream in(file);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Offers every picture in camera order; the last one completes the round.
void offerRound(calibrate::MatGuideSession& session, const std::vector<cv::Mat>& pictures) {
  for (std::size_t c = 0; c < pictures.size(); ++c) {
    EXPECT_EQ(session.offer(c, pictures[c]), c + 1 == pictures.size()) << "camera " << c;
  }
}

// A failed session's mounts are refused: CalibrationError, and the rig is byte for byte as it was.
void expectRefusedToWrite(const calibrate::MatGuideSession& session,
                          const std::filesystem::path& rig) {
  const std::string before = contents(rig);
  try {
    calibrate::writeMatMounts(*session.result(), {std::nullopt, rig}, "test", "see the page");
    ADD_FAILURE() << "a failed session's mounts were written";
  } catch (const processing::CalibrationError& error) {
    EXPECT_THAT(error.what(), HasSubstr("; nothing was written"));
  }
  EXPECT_EQ(contents(rig), before);
  EXPECT_FALSE(std::filesystem::exists(rig.string() + ".part"));
}

TEST(MatGuideSession, FisheyeRigPassesNearTheTruthAndItsMountsGoIntoTheRig) {
  const auto& scene = fisheyeScene();
  calibrate::MatGuideSession session(settingsFor(scene, scene.mat));
  EXPECT_THAT(session.hints(), Contains("waiting for camera front's picture"));
  EXPECT_THAT(calibrate::matGuideStateJson(session, {}), HasSubstr(R"("phase": "waiting")"));
  for (std::size_t c = 0; c + 1 < scene.pictures.size(); ++c) {
    EXPECT_FALSE(session.offer(c, scene.pictures[c]));
  }
  EXPECT_FALSE(session.result());  // one camera still without a picture: nothing to solve
  EXPECT_THAT(session.hints(),
              Contains(fmt::format("waiting for camera {}'s picture", scene.truth.back().name)));
  ASSERT_TRUE(session.offer(scene.pictures.size() - 1, scene.pictures.back()));
  ASSERT_TRUE(session.passed()) << fmt::format("{}", fmt::join(session.hints(), "\n"));
  EXPECT_EQ(session.solves(), 1U);

  const auto& result = *session.result();
  for (std::size_t c = 0; c < result.cameras.size(); ++c) {
    const auto& camera = result.cameras[c];
    const PoseError nominalError =
        poseError(session.settings().cameras[c].pose, scene.truth[c].pose);
    const PoseError error = poseError(camera.solve->pose, scene.truth[c].pose);
    EXPECT_LT(error.positionCm, 1.0) << camera.camera;
    EXPECT_LT(error.rotationDeg, 0.2) << camera.camera;
    const std::string figure = fmt::format(
        "{:.3f} cm {:.4f} deg (started {:.1f} cm {:.2f} deg off), RMS {:.3f} px", error.positionCm,
        error.rotationDeg, nominalError.positionCm, nominalError.rotationDeg, camera.solve->rmsPx);
    ::testing::Test::RecordProperty(camera.camera + "_mount_error", figure);
    std::cout << camera.camera << ": " << figure << "\n";
  }
  ASSERT_EQ(result.seams.size(), 4U);
  const double limit = session.settings().limits.maxSeamCm;
  for (const auto& seam : result.seams) {
    EXPECT_LT(seam.rmsCm, limit) << seam.first << "|" << seam.second;
    EXPECT_LT(seam.rmsCm, 1.0) << seam.first << "|" << seam.second;
    const std::string figure =
        fmt::format("RMS {:.3f} cm, max {:.3f} cm (limit {:g} cm)", seam.rmsCm, seam.maxCm, limit);
    ::testing::Test::RecordProperty(fmt::format("seam_{}_{}", seam.first, seam.second), figure);
    std::cout << seam.first << "|" << seam.second << ": " << figure << "\n";
  }
  // The stitched top view covers the grid, and the ground under each board is seen.
  const auto& grid = session.topViewGrid();
  ASSERT_EQ(session.topView().size(), grid.size);
  for (const auto& board : scene.mat.boards) {
    const cv::Point pixel(grid.pixelOf(board.print.centre));
    ASSERT_TRUE(cv::Rect({}, grid.size).contains(pixel)) << board.print.name;
    EXPECT_GT(cv::norm(session.topView().at<cv::Vec3b>(pixel)), 0) << board.print.name;
  }
  EXPECT_EQ(calibrate::matGuideFrame(session).size(), calibrate::kMatGuideFrameSize);
  const std::string json = calibrate::matGuideStateJson(session, {});
  EXPECT_THAT(json, AllOf(HasSubstr(R"("phase": "passed")"), HasSubstr(R"("seamLimitCm": 3)"),
                          HasSubstr(R"("cameras": "front|right")")));

  // A later picture changes nothing: the mounts are final.
  EXPECT_FALSE(session.offer(0, scene.pictures[0]));
  EXPECT_EQ(session.solves(), 1U);

  const surroundd::testing::TempDir dir;
  const auto rig = nominalRigFile(dir, session.settings());
  const auto written =
      calibrate::writeMatMounts(result, {dir / "mounts.yaml", rig}, "test", "see the page");
  EXPECT_EQ(written.size(), 2U);
  const auto updated = daemon::loadRigFile(rig);
  ASSERT_EQ(updated.size(), scene.truth.size());
  for (std::size_t c = 0; c < updated.size(); ++c) {
    const PoseError error = poseError(updated[c].calibration.pose, scene.truth[c].pose);
    EXPECT_LT(error.positionCm, 1.0) << updated[c].calibration.name;
    EXPECT_LT(error.rotationDeg, 0.2) << updated[c].calibration.name;
  }
}

// Boards printed with 20 cm squares, declared as 25 cm: no camera can be posed from them as
// declared, so the session fails, names the problems, and writes nothing.
TEST(MatGuideSession, AMatDeclaredAtTheWrongSizeIsRefused) {
  const auto& scene = fisheyeScene();
  processing::MatLayout declared = scene.mat;
  for (auto& board : declared.boards) board.print.board.squareM = 0.25;
  calibrate::MatGuideSession session(settingsFor(scene, declared));
  offerRound(session, scene.pictures);
  ASSERT_TRUE(session.result());
  EXPECT_FALSE(session.passed());
  EXPECT_THAT(session.hints(), Contains(HasSubstr("camera front: ")));
  EXPECT_THAT(calibrate::matGuideStateJson(session, {}),
              AllOf(HasSubstr(R"("phase": "failed")"), HasSubstr(R"("passed": false)")));
  const surroundd::testing::TempDir dir;
  expectRefusedToWrite(session, nominalRigFile(dir, session.settings()));
}

// The right camera sees bare ground (its two boards not laid yet): it fails naming each board,
// its neighbours' seams with it are unchecked, nothing is written. Once the boards are there, the
// next round of pictures solves again and passes.
TEST(MatGuideSession, ACameraWithoutBoardsFailsUntilItsBoardsAreThere) {
  const auto& scene = fisheyeScene();
  const auto right =
      static_cast<std::size_t>(std::find_if(scene.truth.begin(), scene.truth.end(),
                                            [](const auto& c) { return c.name == "right"; }) -
                               scene.truth.begin());
  ASSERT_LT(right, scene.truth.size());
  auto pictures = scene.pictures;
  pictures[right] = groundView(scene.truth[right], {}, 7);
  calibrate::MatGuideSession session(settingsFor(scene, scene.mat));
  offerRound(session, pictures);
  ASSERT_TRUE(session.result());
  EXPECT_FALSE(session.passed());
  const auto hints = session.hints();
  EXPECT_THAT(hints, Contains(HasSubstr("camera right: board 'front_right'")));
  EXPECT_THAT(hints, Contains(HasSubstr("camera right: board 'right_back'")));
  EXPECT_THAT(hints, Contains(HasSubstr("seam front|right unchecked")));
  EXPECT_TRUE(session.result()->cameras[0].passed());  // front sees its boards
  const surroundd::testing::TempDir dir;
  expectRefusedToWrite(session, nominalRigFile(dir, session.settings()));

  // One camera's new picture is not a round; all four are.
  EXPECT_FALSE(session.offer(right, scene.pictures[right]));
  EXPECT_EQ(session.solves(), 1U);
  offerRound(session, scene.pictures);
  EXPECT_EQ(session.solves(), 2U);
  EXPECT_TRUE(session.passed()) << fmt::format("{}", fmt::join(session.hints(), "\n"));
}

// A mat that names a camera the rig does not have is refused when the session is made.
TEST(MatGuideSession, ABoardSeenByAnUnknownCameraIsRefused) {
  const auto& scene = fisheyeScene();
  processing::MatLayout mat = scene.mat;
  mat.boards[0].seenBy = {"front", "roof"};
  EXPECT_THROW(calibrate::MatGuideSession(settingsFor(scene, mat)), processing::CalibrationError);
}

}  // namespace
}  // namespace surroundd::calibration::testing
