// The guidelines as a layer of the views: the scene gets new lines only when what they show
// changes by a tenth of a degree or more (or they are hidden), and a picture made on the CPU gets
// them as the view shows them, read back from OpenGL once per change.

#include "render/guideline_layer.hpp"

#include <memory>
#include <optional>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "processing/surround_mesh.hpp"
#include "render/egl_context.hpp"

namespace surroundd::render {
namespace {

processing::PanoramaGeometry panoramaGeometry() {
  processing::PanoramaGeometry p;
  p.size = {512, 256};
  p.centre = {0, 0, 1.9};
  return p;
}

// CV_8U: where any of a BGR picture's channels is lit.
cv::Mat litIn(const cv::Mat& bgr) {
  cv::Mat brightest;
  cv::reduce(bgr.reshape(1, static_cast<int>(bgr.total())), brightest, 1, cv::REDUCE_MAX);
  return brightest.reshape(1, bgr.rows) > 0;
}

ViewSettings cutting() {
  ViewSettings settings;
  settings.transitionS = 0;
  return settings;
}

class GuidelineLayerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { context = std::make_unique<EglContext>(); }
  static void TearDownTestSuite() { context.reset(); }
  inline static std::unique_ptr<EglContext> context;

  SurroundScene scene{processing::buildSurroundMesh(processing::MeshSettings{}, panoramaGeometry()),
                      panoramaGeometry(),
                      processing::VehicleDimensions{},
                      {320, 180}};
  GuidelineLayer layer{scene, processing::VehicleDimensions{}, GuidelineSettings{}};
};

TEST_F(GuidelineLayerTest, TheSceneGetsNewLinesOnlyWhenWhatTheyShowChanges) {
  EXPECT_FALSE(layer.shown());
  EXPECT_FALSE(scene.hasGuidelines());
  const int hidden = layer.version();

  layer.show(GuidelinePose{Travel::kReverse, 0});
  EXPECT_TRUE(layer.shown());
  EXPECT_TRUE(scene.hasGuidelines());
  const int straight = layer.version();
  EXPECT_NE(straight, hidden);

  layer.show(GuidelinePose{Travel::kReverse, 0.04});  // within the same tenth of a degree
  EXPECT_EQ(layer.version(), straight);
  layer.show(GuidelinePose{Travel::kReverse, 0.06});
  const int turned = layer.version();
  EXPECT_NE(turned, straight);
  layer.show(GuidelinePose{Travel::kForward, 0.06});
  const int forward = layer.version();
  EXPECT_NE(forward, turned);

  layer.show(std::nullopt);
  EXPECT_FALSE(layer.shown());
  EXPECT_FALSE(scene.hasGuidelines());
  const int hiddenAgain = layer.version();
  EXPECT_NE(hiddenAgain, forward);
  layer.show(std::nullopt);
  EXPECT_EQ(layer.version(), hiddenAgain);
}

// Laid over a grey picture of the top view: the guidelines' pixels as the view's own layer has
// them, the rest untouched; while the layer's version stays, the lines are not read back again
// (the scene's lines changed behind the layer's back do not show), and once it changes they are.
TEST_F(GuidelineLayerTest, APictureGetsTheLinesAsTheViewShowsThemReadBackOncePerChange) {
  SurroundView view(scene, {320, 240}, ViewKind::kTop, cutting());
  layer.show(GuidelinePose{Travel::kReverse, 0});
  const cv::Mat expected = view.guidelineLayer(0).clone();
  const cv::Mat grey(expected.size(), CV_8UC3, cv::Scalar::all(50));

  GuidelineOverlay overlay;
  cv::Mat picture = grey.clone();
  overlay.layOver(view, layer, picture);
  const cv::Mat lit = litIn(expected);
  ASSERT_GT(cv::countNonZero(lit), 200) << "the top view shows the reversing lines";
  EXPECT_EQ(cv::norm(picture, expected, cv::NORM_INF, lit), 0.0);
  EXPECT_EQ(cv::norm(picture, grey, cv::NORM_INF, ~lit), 0.0);

  std::vector<GuidelineVertex> elsewhere;
  guidelines(processing::VehicleDimensions{}, GuidelineSettings{}, Travel::kForward, 300,
             elsewhere);
  scene.setGuidelines(elsewhere);
  cv::Mat again = grey.clone();
  overlay.layOver(view, layer, again);
  EXPECT_EQ(cv::norm(again, picture, cv::NORM_INF), 0.0) << "read back again without a change";

  layer.show(GuidelinePose{Travel::kReverse, 300});
  cv::Mat turned = grey.clone();
  overlay.layOver(view, layer, turned);
  const cv::Mat turnedLines = view.guidelineLayer(0).clone();
  EXPECT_EQ(cv::norm(turned, turnedLines, cv::NORM_INF, litIn(turnedLines)), 0.0);
  EXPECT_GT(cv::norm(turned, picture, cv::NORM_L1), 0.0) << "the turned lines are laid";
}

}  // namespace
}  // namespace surroundd::render
