// The surround view on whatever EGL offers (Mesa's llvmpipe here): ground points land where the
// top view's geometry puts them, each view matches its golden picture, views switch at run time,
// and set-up errors say what failed.

#include "render/surround_view.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <numbers>
#include <numeric>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "render/egl_context.hpp"
#include "render/render_error.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::render {
namespace {

// A panorama whose every pixel says where it is: red and green run up and down (a triangle
// wave) along columns and rows, blue counts the 256-pixel blocks. Linear filtering between
// neighbours stays decodable because the waves never jump.
cv::Mat codedPanorama(cv::Size size) {
  cv::Mat image(size, CV_8UC3);
  const auto wave = [](int i) { return (i >> 8) % 2 == 0 ? (i & 255) : 255 - (i & 255); };
  for (int r = 0; r < size.height; ++r) {
    for (int c = 0; c < size.width; ++c) {
      image.at<cv::Vec3b>(r, c) =
          cv::Vec3b(static_cast<std::uint8_t>(30 * (c >> 8) + 128 * (r >> 8)),
                    static_cast<std::uint8_t>(wave(r)), static_cast<std::uint8_t>(wave(c)));
    }
  }
  return image;
}

cv::Point2d decode(const cv::Vec3b& bgr) {
  const int rowBlock = bgr[0] >= 110 ? 1 : 0;
  const int columnBlock = static_cast<int>(std::lround((bgr[0] - 128 * rowBlock) / 30.0));
  const auto unwave = [](int block, int value) {
    return block * 256 + (block % 2 == 0 ? value : 255 - value);
  };
  return {static_cast<double>(unwave(columnBlock, bgr[2])),
          static_cast<double>(unwave(rowBlock, bgr[1]))};
}

processing::PanoramaGeometry testPanorama() {
  processing::PanoramaGeometry p;
  p.size = {1024, 512};
  p.centre = {0, 0, 1.9};
  return p;
}

// Views switched at once: their pictures are compared with their golden ones (the switch itself:
// TransitionsMove...).
ViewSettings cutting() {
  ViewSettings settings;
  settings.transitionS = 0;
  return settings;
}

struct Rendering {
  Rendering(processing::MeshModel model, cv::Size size, ViewKind view)
      : scene(mesh(model), testPanorama(), processing::VehicleDimensions{}, {320, 180}),
        surround(scene, size, view, cutting()) {
    scene.uploadPanorama(codedPanorama(testPanorama().size));
    scene.uploadCamera(surroundd::testing::syntheticPicture({320, 180}, 3));
  }
  static processing::SurroundMesh mesh(processing::MeshModel model) {
    processing::MeshSettings settings;
    settings.model = model;
    return processing::buildSurroundMesh(settings, testPanorama());
  }
  cv::Mat draw(double timeS = 0) {
    surround.draw(timeS);
    return surround.collect().clone();
  }

  SurroundScene scene;
  SurroundView surround;
};

class SurroundViewTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { context = std::make_unique<EglContext>(); }
  static void TearDownTestSuite() { context.reset(); }
  inline static std::unique_ptr<EglContext> context;
};

TEST_F(SurroundViewTest, MakesAHeadlessContext) {
  RecordProperty("egl", context->description());
  EXPECT_NE(context->description().find("OpenGL ES 3"), std::string::npos)
      << context->description();
}

// Where a ground point lands in a perspective view's picture (pixel centres at integers), by the
// view's projection: clip space with the picture's rows top first.
cv::Point2d projected(ViewKind view, cv::Size size, cv::Point2d ground) {
  const cv::Matx44f m = viewProjection(*perspectivePose(view, ViewSettings{}, size, 0), size);
  const cv::Vec4f clip =
      m * cv::Vec4f(static_cast<float>(ground.x), static_cast<float>(ground.y), 0, 1);
  return {(clip[0] / clip[3] + 1) / 2.0 * size.width - 0.5,
          (clip[1] / clip[3] + 1) / 2.0 * size.height - 0.5};
}

// Where the top view's geometry puts a ground point: front up, left on the left, the shorter side
// spanning 2 x range.
cv::Point2d onTopView(cv::Size size, cv::Point2d ground) {
  const double pixelsPerMetre = std::min(size.width, size.height) / (2 * ViewSettings{}.topRangeM);
  return {size.width / 2.0 - ground.y * pixelsPerMetre - 0.5,
          size.height / 2.0 - ground.x * pixelsPerMetre - 0.5};
}

// Ground points at known vehicle-frame positions: in the view they must land where its geometry
// says (the top view's own, or the view's projection), and the panorama pixel seen there must be
// the one that looks at that ground point.
void expectGroundPointsLandOnTheirPixels(processing::MeshModel model,
                                         std::initializer_list<cv::Point2d> groundPoints,
                                         ViewKind view = ViewKind::kTop) {
  const cv::Size size(640, 480);
  Rendering rendering(model, size, view);
  const cv::Mat picture = rendering.draw();
  const processing::PanoramaGeometry panorama = testPanorama();
  const auto pictureOf = [&](cv::Point2d ground) {
    return view == ViewKind::kTop ? onTopView(size, ground) : projected(view, size, ground);
  };
  for (const cv::Point2d& ground : groundPoints) {
    const cv::Point2d expected = pictureOf(ground);
    const cv::Point2d wanted = panorama.pixel(cv::Vec3d(ground.x, ground.y, 0) - panorama.centre);
    std::vector<std::pair<double, cv::Point>> seenFrom;  // panorama pixel error, picture pixel
    for (int y = static_cast<int>(expected.y) - 6; y <= static_cast<int>(expected.y) + 6; ++y) {
      for (int x = static_cast<int>(expected.x) - 6; x <= static_cast<int>(expected.x) + 6; ++x) {
        const cv::Point2d seen = decode(picture.at<cv::Vec3b>(y, x));
        double dc = std::abs(seen.x - wanted.x);
        dc = std::min(dc, panorama.size.width - dc);
        seenFrom.emplace_back(std::hypot(dc, seen.y - wanted.y), cv::Point(x, y));
      }
    }
    const double bestError =
        std::ranges::min_element(seenFrom, {}, &std::pair<double, cv::Point>::first)->first;
    EXPECT_LT(bestError, 2.0) << "ground point " << ground << ": panorama pixel " << wanted
                              << " not seen near " << expected;
    // Drawn at the middle of the pixels that see it best, to within 2 pixels or one panorama
    // pixel's footprint there, whichever is larger: the colours say whole panorama pixels, and
    // llvmpipe rounds them a level apart on arm64 and x86. Far out on the flat disk a panorama
    // pixel spans several picture pixels (a point 8 m out lands 2.5 px apart).
    cv::Point2d drawn(0, 0);
    int best = 0;
    for (const auto& [error, at] : seenFrom) {
      if (error > bestError) continue;
      drawn += cv::Point2d(at);
      ++best;
    }
    drawn *= 1.0 / best;
    const auto panoramaPixelsPerMetre = [&](const cv::Vec3d& step) {
      const cv::Vec3d at(ground.x, ground.y, 0);
      const cv::Point2d d =
          panorama.pixel(at + step - panorama.centre) - panorama.pixel(at - step - panorama.centre);
      const double dc = std::abs(d.x);
      return std::hypot(std::min(dc, panorama.size.width - dc), d.y) / (2 * cv::norm(step));
    };
    const auto pictureStep = [&](cv::Point2d step) {
      return cv::norm(pictureOf(ground + step) - pictureOf(ground - step)) / (2 * cv::norm(step));
    };
    const double footprint =
        std::max(pictureStep({0.01, 0}) / panoramaPixelsPerMetre({0.01, 0, 0}),
                 pictureStep({0, 0.01}) / panoramaPixelsPerMetre({0, 0.01, 0}));
    EXPECT_LE(cv::norm(drawn - expected), std::max(2.0, footprint))
        << "ground point " << ground << " drawn at " << drawn << " (" << best
        << " pixels), expected " << expected << "; a panorama pixel spans " << footprint;
  }
}

TEST_F(SurroundViewTest, TopViewPutsGroundPointsOnTheirPixelsOnTheBowlFloor) {
  expectGroundPointsLandOnTheirPixels(processing::MeshModel::kBowl, {{3.5, 0},
                                                                     {-3.5, 0},
                                                                     {0, 2.5},
                                                                     {0, -2.5},
                                                                     {3, 2.5},
                                                                     {-3, 2.5},
                                                                     {3, -2.5},
                                                                     {4.5, 1.5},
                                                                     {-1, 4.5}});
}

// The rear view looks back from above the front: ground behind the car lands where its
// projection says (on the bowl's floor; beyond it the wall rises), out to 10 m in the picture;
// the projection itself agrees with the top view's own geometry.
TEST_F(SurroundViewTest, RearViewPutsTheGroundBehindTheCarOnItsPixels) {
  const cv::Size size(640, 480);
  for (const cv::Point2d ground : {cv::Point2d(3.5, 0), cv::Point2d(-3, 2.5)}) {
    EXPECT_LT(cv::norm(projected(ViewKind::kTop, size, ground) - onTopView(size, ground)), 1e-3);
  }
  for (const cv::Point2d ground : {cv::Point2d(-4, 0), cv::Point2d(-10, 0)}) {
    const cv::Point2d at = projected(ViewKind::kRear, size, ground);
    EXPECT_NEAR(at.x, size.width / 2.0 - 0.5, 1e-3);  // straight behind: the middle column
    EXPECT_GT(at.y, 0);
    EXPECT_LT(at.y, size.height);
  }
  EXPECT_LT(projected(ViewKind::kRear, size, {-10, 0}).y,
            projected(ViewKind::kRear, size, {-4, 0}).y);
  expectGroundPointsLandOnTheirPixels(processing::MeshModel::kBowl,
                                      {{-3.5, 0}, {-4.5, 1.5}, {-4.5, -1.5}, {-4, -1}, {-3, 3}},
                                      ViewKind::kRear);
}

// The guidelines in the top view: at each steering angle, points of both wheels' paths and the
// markers' middles are drawn where the steering model puts them (render/guidelines.hpp), within
// 2 pixels: the middle of the guideline's pixels near each point. Magenta paths and cyan markers:
// colours the coded panorama never has (its blue stays below 220).
TEST_F(SurroundViewTest, GuidelinesLandWhereTheSteeringModelPutsThem) {
  const cv::Size size(640, 480);
  Rendering rendering(processing::MeshModel::kBowl, size, ViewKind::kTop);
  GuidelineSettings settings;
  settings.pathColour = {1, 0, 1};
  settings.markerColours.assign(settings.markersM.size(), {0, 1, 1});
  const processing::VehicleDimensions car;
  std::vector<GuidelineVertex> vertices;
  // The middle of the pixels of `colour` in a 9 x 9 window about `at`; none if there are none.
  const auto middleOf = [](const cv::Mat& picture, cv::Point2d at, const cv::Vec3b& colour) {
    cv::Point2d sum(0, 0);
    int count = 0;
    for (int y = static_cast<int>(std::lround(at.y)) - 4; y <= std::lround(at.y) + 4; ++y) {
      for (int x = static_cast<int>(std::lround(at.x)) - 4; x <= std::lround(at.x) + 4; ++x) {
        if (cv::norm(picture.at<cv::Vec3b>(y, x), colour, cv::NORM_INF) > 24) continue;
        sum += cv::Point2d(x, y);
        ++count;
      }
    }
    return count == 0 ? std::optional<cv::Point2d>() : std::optional(sum * (1.0 / count));
  };
  for (const auto& [travel, steeringDeg] :
       {std::pair{Travel::kReverse, 0.0}, std::pair{Travel::kReverse, 270.0},
        std::pair{Travel::kReverse, -450.0}, std::pair{Travel::kForward, 360.0}}) {
    SCOPED_TRACE(::testing::Message() << (travel == Travel::kReverse ? "reverse" : "forward")
                                      << " at " << steeringDeg << " deg");
    guidelines(car, settings, travel, steeringDeg, vertices);
    rendering.scene.setGuidelines(vertices);
    const cv::Mat picture = rendering.draw();
    const double sign = travel == Travel::kReverse ? -1 : 1;
    const double overhang = travel == Travel::kReverse ? car.rearOverhangM : car.frontOverhangM;
    double worst = 0;
    // Past the bumper and the car's dark patch, short of the path's end.
    for (const double past : {0.6, 1.2, 1.8, 2.4}) {
      for (const int side : {1, -1}) {
        const cv::Point2d point =
            wheelPathPoint(car, travel, steeringDeg, side, sign * (overhang + past));
        const cv::Point2d expected = onTopView(size, point);
        const auto drawn = middleOf(picture, expected, {255, 0, 255});
        ASSERT_TRUE(drawn) << "no path drawn near " << expected << " (" << point << ")";
        worst = std::max(worst, cv::norm(*drawn - expected));
      }
    }
    for (const double marker : settings.markersM) {
      const double distance = sign * (overhang + marker);
      const cv::Point2d middle = (wheelPathPoint(car, travel, steeringDeg, 1, distance) +
                                  wheelPathPoint(car, travel, steeringDeg, -1, distance)) *
                                 0.5;
      const auto drawn = middleOf(picture, onTopView(size, middle), {255, 255, 0});
      ASSERT_TRUE(drawn) << "no marker at " << marker << " m";
      worst = std::max(worst, cv::norm(*drawn - onTopView(size, middle)));
    }
    EXPECT_LE(worst, 2.0);
    RecordProperty(fmt::format("worst_px_{}_{}", travel == Travel::kReverse ? "reverse" : "forward",
                               steeringDeg),
                   fmt::format("{:.2f}", worst));
  }
  // None: nothing of them is left.
  rendering.scene.setGuidelines({});
  const cv::Mat none = rendering.draw();
  cv::Mat magenta;
  cv::inRange(none, cv::Scalar(231, 0, 231), cv::Scalar(255, 24, 255), magenta);
  EXPECT_EQ(cv::countNonZero(magenta), 0);
}

TEST_F(SurroundViewTest, TopViewPutsGroundPointsOnTheirPixelsOnTheFlatDisk) {
  expectGroundPointsLandOnTheirPixels(processing::MeshModel::kFlat,
                                      {{7, 0}, {0, 6.5}, {-5, -5}, {-7.5, 1}, {2, -8}});
}

// Each view against its golden picture (rendered once on llvmpipe and reviewed). Set
// SURROUNDD_UPDATE_GOLDEN=1 to write new ones after an intended change.
void expectMatchesGolden(const cv::Mat& picture, const std::string& name) {
  const std::filesystem::path golden =
      std::filesystem::path(SURROUNDD_SOURCE_DIR) / "tests/render/golden" / (name + ".png");
  // NOLINTNEXTLINE(concurrency-mt-unsafe): read once, before any thread of the test starts.
  if (std::getenv("SURROUNDD_UPDATE_GOLDEN") != nullptr) {
    cv::imwrite(golden.string(), picture);
    GTEST_SKIP() << "wrote " << golden;
  }
  const cv::Mat expected = cv::imread(golden.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(expected.empty()) << "no golden picture " << golden;
  ASSERT_EQ(expected.size(), picture.size());
  cv::Mat difference;
  cv::absdiff(picture, expected, difference);
  difference = difference.reshape(1);
  const double mean = cv::mean(difference)[0];
  const double farOff = static_cast<double>(cv::countNonZero(difference > 24)) /
                        static_cast<double>(difference.total());
  const std::filesystem::path actual =
      std::filesystem::temp_directory_path() / ("surroundd-" + name + "-actual.png");
  if (mean > 0.5 || farOff > 0.002) cv::imwrite(actual.string(), picture);
  EXPECT_LE(mean, 0.5) << name << ": mean difference to the golden picture; this run's is "
                       << actual;
  EXPECT_LE(farOff, 0.002) << name << ": share of values more than 24 levels off; see " << actual;
}

TEST_F(SurroundViewTest, EveryViewMatchesItsGoldenPicture) {
  Rendering rendering(processing::MeshModel::kBowl, {320, 240}, ViewKind::kTop);
  for (const ViewKind view :
       {ViewKind::kTop, ViewKind::kPanorama360, ViewKind::kOrbit, ViewKind::kSplit}) {
    SCOPED_TRACE(toString(view));
    rendering.surround.setView(view);
    expectMatchesGolden(rendering.draw(3.0), std::string("view_") + toString(view));
  }
}

TEST_F(SurroundViewTest, SwitchingTheViewChangesThePictureAndBack) {
  Rendering rendering(processing::MeshModel::kBowl, {320, 240}, ViewKind::kTop);
  const cv::Mat top = rendering.draw();
  const uchar* buffer = rendering.surround.collect().data;
  rendering.surround.setView(ViewKind::kOrbit);
  EXPECT_EQ(rendering.surround.view(), ViewKind::kOrbit);
  const cv::Mat orbit = rendering.draw();
  rendering.surround.setView(ViewKind::kTop);
  const cv::Mat topAgain = rendering.draw();
  EXPECT_GT(cv::norm(top, orbit, cv::NORM_L1) / static_cast<double>(top.total()), 10.0);
  EXPECT_EQ(cv::norm(top, topAgain, cv::NORM_INF), 0.0);
  EXPECT_EQ(rendering.surround.collect().data, buffer) << "the picture was reallocated";
}

// A switch of view takes ViewSettings::transitionS of stream time from the first draw after it:
// between top and orbit the eye moves (starting from the old picture, ending on the new), between
// others the two pictures fade; the view moves while it lasts.
TEST_F(SurroundViewTest, ASwitchMovesTheEyeOrFadesOverTheTransitionTime) {
  Rendering cut(processing::MeshModel::kBowl, {320, 240}, ViewKind::kTop);
  const auto cutTo = [&](ViewKind view, double timeS) {
    cut.surround.setView(view);
    return cut.draw(timeS);
  };
  SurroundView view(cut.scene, {320, 240}, ViewKind::kTop, ViewSettings{});  // 0.4 s
  const auto draw = [&](double timeS) {
    view.draw(timeS);
    return view.collect().clone();
  };
  const auto apart = [](const cv::Mat& a, const cv::Mat& b) {
    return cv::norm(a, b, cv::NORM_L1) / static_cast<double>(a.total());
  };
  EXPECT_FALSE(view.moves());
  view.setView(ViewKind::kOrbit);
  EXPECT_TRUE(view.moves());
  EXPECT_EQ(cv::norm(draw(1.0), cutTo(ViewKind::kTop, 1.0), cv::NORM_INF), 0.0);
  const cv::Mat midway = draw(1.2);
  EXPECT_GT(apart(midway, cutTo(ViewKind::kTop, 1.2)), 10.0);
  EXPECT_GT(apart(midway, cutTo(ViewKind::kOrbit, 1.2)), 10.0);
  EXPECT_EQ(cv::norm(draw(1.4), cutTo(ViewKind::kOrbit, 1.4), cv::NORM_INF), 0.0);

  // Orbit to 360: faded, half and half at half the time.
  view.setView(ViewKind::kPanorama360);
  EXPECT_TRUE(view.moves());
  draw(2.0);
  cv::Mat half;
  cv::addWeighted(cutTo(ViewKind::kOrbit, 2.2), 0.5, cutTo(ViewKind::kPanorama360, 2.2), 0.5, 0,
                  half);
  EXPECT_GE(cv::PSNR(draw(2.2), half), 40.0);
  EXPECT_EQ(cv::norm(draw(2.4), cutTo(ViewKind::kPanorama360, 2.4), cv::NORM_INF), 0.0);
  EXPECT_FALSE(view.moves());
}

// The eye's path from the top view to the orbit's start, drawn at 30 pictures a second over the
// default 0.4 s: it starts and stops gently and never jumps, at most 1.5 times the mean step
// (smoothstep's peak speed).
TEST(ViewTransition, TheEyeStartsAndStopsGentlyAndNeverJumps) {
  const ViewSettings settings;
  const cv::Size size(1280, 720);
  const ViewPose top = topViewPose(settings, size);
  const ViewPose orbit = orbitViewPose(settings, 0);
  const int frames = static_cast<int>(std::lround(settings.transitionS * 30));
  std::vector<double> steps;
  for (int k = 1; k <= frames; ++k) {
    const ViewPose a = poseBetween(top, orbit, (k - 1.0) / frames);
    const ViewPose b = poseBetween(top, orbit, static_cast<double>(k) / frames);
    steps.push_back(cv::norm(b.eye - a.eye));
  }
  const double path = std::accumulate(steps.begin(), steps.end(), 0.0);
  const double mean = path / frames;
  EXPECT_NEAR(cv::norm(poseBetween(top, orbit, 1).eye - orbit.eye), 0.0, 1e-9);
  EXPECT_LE(*std::max_element(steps.begin(), steps.end()), 1.5 * mean + 1e-9);
  EXPECT_LT(steps.front(), 0.3 * mean);
  EXPECT_LT(steps.back(), 0.3 * mean);
  RecordProperty("eye_path_m", std::to_string(path));
  RecordProperty("largest_step_m", std::to_string(*std::max_element(steps.begin(), steps.end())));
}

TEST_F(SurroundViewTest, OrbitMovesWithTimeAndReadBackIsCollectedOnce) {
  Rendering rendering(processing::MeshModel::kBowl, {320, 240}, ViewKind::kOrbit);
  EXPECT_FALSE(rendering.surround.pending());
  rendering.surround.draw(0.0);
  EXPECT_TRUE(rendering.surround.pending());
  const cv::Mat first = rendering.surround.collect().clone();
  EXPECT_FALSE(rendering.surround.pending());
  EXPECT_EQ(cv::norm(first, rendering.surround.collect(), cv::NORM_INF), 0.0);
  const cv::Mat later = rendering.draw(5.0);  // a quarter turn on
  EXPECT_GT(cv::norm(first, later, cv::NORM_L1) / static_cast<double>(first.total()), 10.0);
}

// On llvmpipe draw() only starts the rasterization and collect() reads the framebuffer: a guideline
// layer drawn into that framebuffer in between must not become the pending picture.
TEST_F(SurroundViewTest, APendingPictureOutlivesAGuidelineLayerDrawnBeforeItIsCollected) {
  Rendering rendering(processing::MeshModel::kBowl, {320, 240}, ViewKind::kTop);
  std::vector<GuidelineVertex> vertices;
  guidelines(processing::VehicleDimensions{}, GuidelineSettings{}, Travel::kReverse, 0, vertices);
  rendering.scene.reserveGuidelines(vertices.size());
  rendering.scene.setGuidelines(vertices);
  const cv::Mat expected = rendering.draw();
  rendering.surround.draw(0);
  const cv::Mat layer = rendering.surround.guidelineLayer(0).clone();
  EXPECT_GT(cv::countNonZero(layer.reshape(1)), 0) << "the layer shows the guidelines";
  EXPECT_GT(cv::norm(layer, expected, cv::NORM_L1) / static_cast<double>(expected.total()), 10.0)
      << "the layer differs from the picture";
  ASSERT_TRUE(rendering.surround.pending());
  EXPECT_EQ(cv::norm(rendering.surround.collect(), expected, cv::NORM_INF), 0.0);
}

// finished() says when collect() would not wait: never before a draw or after the collection,
// and once the drawing is done (polled, as the pipeline does while it waits for frames), with
// the picture the draw made.
TEST_F(SurroundViewTest, APictureIsFinishedOnceDrawnAndNotOnceCollected) {
  Rendering rendering(processing::MeshModel::kBowl, {320, 240}, ViewKind::kTop);
  EXPECT_FALSE(rendering.surround.finished());
  const cv::Mat expected = rendering.draw();
  EXPECT_FALSE(rendering.surround.finished());
  rendering.surround.draw(0);
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!rendering.surround.finished() && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_TRUE(rendering.surround.finished());
  EXPECT_EQ(cv::norm(rendering.surround.collect(), expected, cv::NORM_INF), 0.0);
  EXPECT_FALSE(rendering.surround.finished());
}

TEST_F(SurroundViewTest, RefusesPicturesOfTheWrongSize) {
  Rendering rendering(processing::MeshModel::kBowl, {320, 240}, ViewKind::kTop);
  EXPECT_THROW(rendering.scene.uploadPanorama(cv::Mat(100, 200, CV_8UC3)), std::invalid_argument);
  EXPECT_THROW(rendering.scene.uploadCamera(cv::Mat(180, 320, CV_8UC1)), std::invalid_argument);
  EXPECT_THROW(SurroundView(rendering.scene, {321, 240}, ViewKind::kTop, ViewSettings{}),
               std::invalid_argument);
}

TEST_F(SurroundViewTest, ShaderErrorsCarryTheDriversLog) {
  try {
    ShaderProgram broken("broken", "#version 300 es\nvoid main() { gl_Position = vec4(x); }",
                         "#version 300 es\nvoid main() {}");
    FAIL() << "a shader with an undeclared name compiled";
  } catch (const RenderError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("'broken'"), std::string::npos) << message;
    EXPECT_NE(message.find("vertex shader does not compile"), std::string::npos) << message;
    EXPECT_NE(message.find('x'), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace surroundd::render
