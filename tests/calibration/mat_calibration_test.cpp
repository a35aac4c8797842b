// Camera poses from a generated calibration mat (a large board in each overlap of two neighbouring
// cameras, optionally more ahead), every camera from one picture: poses within 1 cm and 0.2
// degrees of the truth on the 190-degree fisheye rig and the paper's pinhole rig, starting from a
// rig file a few centimetres and degrees off; symmetric boards oriented by the nominal pose; and
// every way a mat can fail is a named problem.

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/calibration/mat_calibration_support.hpp"

namespace surroundd::calibration::testing {
namespace {

using ::testing::AllOf;
using ::testing::Contains;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

void expectEveryCameraPosed(const MatScene& scene, bool symmetric) {
  const auto views = nominalViews(scene, scene.pictures);
  const auto result = processing::calibrateFromMat(scene.mat, views);
  EXPECT_THAT(result.problems, IsEmpty());
  for (std::size_t c = 0; c < result.cameras.size(); ++c) {
    const auto& camera = result.cameras[c];
    SCOPED_TRACE(camera.camera);
    EXPECT_THAT(camera.problems, IsEmpty());
    ASSERT_TRUE(camera.solve);
    const PoseError error = poseError(camera.solve->pose, scene.truth[c].pose);
    EXPECT_LT(error.positionCm, 1.0);
    EXPECT_LT(error.rotationDeg, 0.2);
    EXPECT_LT(camera.solve->rmsPx, 0.3);
    EXPECT_EQ(camera.detection.found.size(),
              processing::boardsSeenBy(scene.mat, camera.camera).size());
    for (const auto& sighting : camera.detection.found) {
      EXPECT_EQ(sighting.orientedByNominalPose, symmetric);
    }
    ::testing::Test::RecordProperty(
        fmt::format("{}_error", camera.camera),
        fmt::format("{:.3f} cm {:.4f} deg, RMS {:.3f} px, {} of {} boards, {} corners",
                    error.positionCm, error.rotationDeg, camera.solve->rmsPx,
                    camera.detection.found.size(),
                    processing::boardsSeenBy(scene.mat, camera.camera).size(), camera.corners));
  }
  EXPECT_EQ(result.seams.size(), result.cameras.size());
  for (const auto& seam : result.seams) {
    EXPECT_LT(seam.rmsCm, 1.0) << seam.first << "|" << seam.second;
    ::testing::Test::RecordProperty(
        fmt::format("seam_{}_{}", seam.first, seam.second),
        fmt::format("RMS {:.3f} cm, max {:.3f} cm", seam.rmsCm, seam.maxCm));
  }
  EXPECT_TRUE(result.passed());
}

// 7x6 boards of 20 cm squares, one at each corner of the car.
const MatScene& fisheyeScene() {
  static const MatScene kScene = matScene("fisheye.yaml", {{{7, 6}, 0.2}, {}});
  return kScene;
}

TEST(MatCalibration, EveryCameraOfTheFisheyeRigFromFourCornerBoards) {
  expectEveryCameraPosed(fisheyeScene(), false);
}

// The paper's cameras overlap by about 10 degrees: the corner boards are small (5x4, 12 cm), so
// each camera also gets one straight ahead.
TEST(MatCalibration, EveryCameraOfThePinholeRigFromCornerBoardsAndBoardsAhead) {
  expectEveryCameraPosed(
      matScene("paper.yaml", {{{5, 4}, 0.12}, {"front", "right", "back", "left"}}), false);
}

// 6x6 boards look the same after a quarter turn: the nominal mount picks the orientation.
TEST(MatCalibration, SquareBoardsOrientedByTheNominalMount) {
  expectEveryCameraPosed(matScene("fisheye.yaml", {{{6, 6}, 0.2}, {}}), true);
}

TEST(MatCalibration, BoardSymmetry) {
  using processing::BoardSymmetry;
  EXPECT_EQ(processing::symmetryOf({{7, 6}, 0.1}), BoardSymmetry::kNone);
  EXPECT_EQ(processing::symmetryOf({{7, 5}, 0.1}), BoardSymmetry::kHalfTurn);
  EXPECT_EQ(processing::symmetryOf({{7, 7}, 0.1}), BoardSymmetry::kHalfTurn);
  EXPECT_EQ(processing::symmetryOf({{6, 6}, 0.1}), BoardSymmetry::kQuarterTurn);
}

std::vector<std::string> problemsOf(const processing::MatCalibration& result,
                                    const std::string& camera) {
  for (const auto& c : result.cameras) {
    if (c.camera == camera) return c.problems;
  }
  return {"no such camera"};
}

// The front_right board is not on the ground at all.
TEST(MatCalibration, ABoardMissingFailsBothItsCamerasAndTheirSeam) {
  const MatScene& scene = fisheyeScene();
  auto drawn = scene.mat;
  drawn.boards.erase(drawn.boards.begin());
  const auto result =
      processing::calibrateFromMat(scene.mat, nominalViews(scene, matPictures(scene.truth, drawn)));
  EXPECT_FALSE(result.passed());
  const std::string missing =
      "board 'front_right': no 7x6 board within 0.6 m of its place in "
      "the layout";
  EXPECT_THAT(problemsOf(result, "front"), ElementsAre(missing));
  EXPECT_THAT(problemsOf(result, "right"), ElementsAre(missing));
  EXPECT_THAT(problemsOf(result, "back"), IsEmpty());
  EXPECT_THAT(result.problems,
              ElementsAre("seam front|right unchecked: board 'front_right' was found by "
                          "neither camera"));
}

// The right camera's view of front_right is blocked: only the front camera sees it.
TEST(MatCalibration, ABoardSeenByOneOfItsTwoCamerasOnly) {
  const MatScene& scene = fisheyeScene();
  auto blocked = scene.mat;
  blocked.boards.erase(blocked.boards.begin());
  auto pictures = scene.pictures;
  pictures[1] = groundView(scene.truth[1], synth::printsOf(blocked), 101);
  const auto result = processing::calibrateFromMat(scene.mat, nominalViews(scene, pictures));
  EXPECT_FALSE(result.passed());
  EXPECT_THAT(problemsOf(result, "front"), IsEmpty());
  EXPECT_THAT(problemsOf(result, "right"),
              ElementsAre("board 'front_right': no 7x6 board within 0.6 m of its place in the "
                          "layout"));
  EXPECT_THAT(result.problems,
              ElementsAre("seam front|right unchecked: board 'front_right' was found by front "
                          "only, not by right"));
}

// A board measured 15 cm off where it lies: a camera that sees it cannot fit its corners and the
// others' together (the left camera's pose bends to fit both of its boards, within 1 px).
TEST(MatCalibration, ABoardOutOfPlaceInTheLayoutFailsOnTheRms) {
  const MatScene& scene = fisheyeScene();
  auto wrong = scene.mat;
  wrong.boards[2].print.centre[0] += 0.15;
  ASSERT_THAT(wrong.boards[2].seenBy, ElementsAre("back", "left"));
  const auto result = processing::calibrateFromMat(wrong, nominalViews(scene, scene.pictures));
  EXPECT_FALSE(result.passed());
  EXPECT_THAT(problemsOf(result, "back"),
              Contains(HasSubstr("is over the limit of 1 px; a board's place, yaw or size in the "
                                 "layout may be wrong (see the per-board RMS)")));
}

// A board whose ends differ, laid the other way round from what the layout says.
TEST(MatCalibration, ABoardTurnedFromItsLayoutYawIsRefused) {
  const MatScene& scene = fisheyeScene();
  auto wrong = scene.mat;
  wrong.boards[1].print.yawDeg += 180;
  // The layout's centre of the inner-corner grid stays where it is: only the order flips.
  const auto result = processing::calibrateFromMat(wrong, nominalViews(scene, scene.pictures));
  EXPECT_FALSE(result.passed());
  EXPECT_THAT(problemsOf(result, wrong.boards[1].seenBy[0]),
              Contains(AllOf(
                  HasSubstr(fmt::format("board '{}': found turned 17", wrong.boards[1].print.name)),
                  HasSubstr(" degrees from its yaw_deg in the layout; is the yaw right, "
                            "or the camera's mount that far off?"))));
}

// A front camera's mount taken with a protractor 4 degrees off (and a tape 5 cm): through it the
// board at its front right corner lies beyond the search's margin. The pose its other board gives
// finds it, and the camera is posed from both.
TEST(MatCalibration, ABoardTheNominalMountMissesIsFoundThroughTheOthersPose) {
  const MatScene& scene = fisheyeScene();
  auto views = nominalViews(scene, scene.pictures);
  processing::Pose& front = views[0].nominal.pose;
  processing::MountAngles angles =
      processing::mountAnglesFromRotation(scene.truth[0].pose.rotation);
  angles.pitchDeg += 4;
  front.rotation = processing::rotationFromMountAngles(angles);
  front.position = scene.truth[0].pose.position + cv::Vec3d(-0.05, 0, 0.05);
  const auto first = processing::findMatBoards(views[0].gray, scene.mat, views[0].nominal);
  ASSERT_EQ(first.missed.size(), 1U) << "the nominal mount finds every board: no test";

  const auto result = processing::calibrateFromMat(scene.mat, views);
  EXPECT_THAT(result.problems, IsEmpty());
  const auto& camera = result.cameras[0];
  EXPECT_THAT(camera.problems, IsEmpty());
  EXPECT_EQ(camera.detection.found.size(), 2U);
  ASSERT_TRUE(camera.solve);
  const PoseError error = poseError(camera.solve->pose, scene.truth[0].pose);
  EXPECT_LT(error.positionCm, 1.0);
  EXPECT_LT(error.rotationDeg, 0.2);
  EXPECT_TRUE(result.passed());
}

TEST(MatCalibration, TooFewCornersAndImplausiblePosesAreRefused) {
  const MatScene& scene = fisheyeScene();
  processing::MatLimits limits;
  limits.minCorners = 100;
  auto result =
      processing::calibrateFromMat(scene.mat, nominalViews(scene, scene.pictures), limits);
  EXPECT_THAT(problemsOf(result, "left"),
              ElementsAre("too few corners: 84, at least 100 are needed"));
  EXPECT_FALSE(result.cameras[3].solve);
  limits = {};
  limits.maxShiftM = 0.01;  // the nominal mount is 7 cm off
  result = processing::calibrateFromMat(scene.mat, nominalViews(scene, scene.pictures), limits);
  EXPECT_THAT(problemsOf(result, "left"),
              Contains(AllOf(HasSubstr("implausible pose: 0.07 m and "),
                             HasSubstr(" degrees from the nominal mount (limits 0.01 m, 15 "
                                       "degrees)"))));
  EXPECT_FALSE(result.passed());
}

}  // namespace
}  // namespace surroundd::calibration::testing
