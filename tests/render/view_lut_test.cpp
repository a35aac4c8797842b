// A fixed view's LUT (processing/stitch/view_lut.hpp), composed from where the renderer samples
// the panorama (SurroundView::panoramaPositions): one gather from the synth_small rig's camera
// images gives the picture the renderer draws from the stitched panorama, for each view that can
// hold still.
//
// Within PSNR 40 dB where the panorama is fine enough not to blur the cameras (twice the rig's
// own, 1024x512: 45.4 to 46.5 dB), over the pixels that show the panorama. At the rig's own
// panorama the render is the blurrier of the two: it samples the panorama bilinearly, each
// panorama pixel itself a bilinear sample of a camera, where the view LUT samples the camera
// once; that alone puts them 38.0 to 39.2 dB apart on synth_small's textured ground, so the bound
// there is 36 dB (the view LUT shifted by one pixel: 31 to 34 dB).

#include "processing/stitch/view_lut.hpp"

#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "common/masked_psnr.hpp"
#include "common/work_pool.hpp"
#include "processing/colour/gain_compensation.hpp"
#include "processing/colour/poisson_correction.hpp"
#include "processing/stitch/stitcher.hpp"
#include "processing/surround_mesh.hpp"
#include "render/egl_context.hpp"
#include "render/surround_view.hpp"
#include "tests/processing/panorama_test_support.hpp"

namespace surroundd::render {
namespace {

// How the panorama is corrected, and so each view's picture.
enum class Correction { kNone, kPoissonMultiplicative, kPoissonAdditive, kGain };

const char* nameOf(Correction correction) {
  switch (correction) {
    case Correction::kNone:
      return "no correction";
    case Correction::kPoissonMultiplicative:
      return "Poisson, multiplicative";
    case Correction::kPoissonAdditive:
      return "Poisson, additive";
    case Correction::kGain:
      return "gain compensation";
  }
  return "?";
}

// The synth_small rig with a panorama of `scale` times its own size: its LUT, its first
// ground-truth frame's camera images, the colour corrections fitted to them, and the scene that
// draws the panorama stitched from them.
struct RigScene {
  explicit RigScene(int scale)
      : truth(processing::testing::smallRecording()),
        settings(scaled(processing::testing::settingsFor(truth), scale)),
        pool(2),
        lut(processing::buildPanoramaLut(truth.rig, settings, pool)),
        images(withOneCameraDarker(processing::testing::truthImages(truth.frames.front()))),
        multiplicative(truth.rig, settings, lut, {}, pool),
        additive(truth.rig, settings, lut, additiveSettings(), pool),
        gains(lut, pool),
        scene(processing::buildSurroundMesh({}, settings.geometry), settings.geometry, {},
              lut.cameraSizes.front()) {
    multiplicative.update(images);
    additive.update(images);
    gains.update(images);
  }
  static processing::PanoramaSettings scaled(processing::PanoramaSettings settings, int scale) {
    settings.geometry.size = settings.geometry.size * scale;
    return settings;
  }
  static std::vector<cv::Mat> withOneCameraDarker(std::vector<cv::Mat> images) {
    images[1].convertTo(images[1], -1, 0.75);
    return images;
  }
  static processing::ColourCorrectionSettings additiveSettings() {
    processing::ColourCorrectionSettings additive;
    additive.field = processing::CorrectionField::kAdditive;
    return additive;
  }

  // Stitches and corrects the panorama and uploads it.
  void show(Correction correction) {
    processing::Stitcher(lut, pool).stitch(images, panorama);
    switch (correction) {
      case Correction::kNone:
        break;
      case Correction::kPoissonMultiplicative:
        multiplicative.apply(panorama);
        break;
      case Correction::kPoissonAdditive:
        additive.apply(panorama);
        break;
      case Correction::kGain:
        gains.apply(panorama);
        break;
    }
    scene.uploadPanorama(panorama);
  }

  // The same correction on a view's picture made through its view LUT.
  void correct(Correction correction, const processing::PanoramaLut& viewLut,
               const cv::Mat& positions, cv::Mat& picture) {
    switch (correction) {
      case Correction::kNone:
        break;
      case Correction::kPoissonMultiplicative:
        multiplicative.applyAt(multiplicative.viewSamples(positions), picture);
        break;
      case Correction::kPoissonAdditive:
        additive.applyAt(additive.viewSamples(positions), picture);
        break;
      case Correction::kGain:
        gains.apply(picture, viewLut);
        break;
    }
  }

  const bench::RecordingTruth& truth;
  processing::PanoramaSettings settings;
  WorkPool pool;
  processing::PanoramaLut lut;
  std::vector<cv::Mat> images;
  processing::PoissonColourCorrection multiplicative;
  processing::PoissonColourCorrection additive;
  processing::GainCompensation gains;
  cv::Mat panorama;
  SurroundScene scene;
};

class ViewLutTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    context = std::make_unique<EglContext>();
    rig = std::make_unique<RigScene>(1);
    fineRig = std::make_unique<RigScene>(2);
  }
  static void TearDownTestSuite() {
    fineRig.reset();
    rig.reset();
    context.reset();
  }

  inline static std::unique_ptr<EglContext> context;
  inline static std::unique_ptr<RigScene> rig;
  inline static std::unique_ptr<RigScene> fineRig;
};

// The renderer's picture of `view` and the view LUT's, with what shows no panorama (the car, the
// background) taken from the renderer's, as a fixed view composites them; and how much of the
// picture shows the panorama.
struct Pictures {
  cv::Mat rendered, direct;
  cv::Mat panoramaShown;  // CV_8U, 255 where the view shows the panorama
};

Pictures drawBoth(RigScene& rig, ViewKind view, double timeS, Correction correction) {
  SurroundView surround(rig.scene, {640, 360}, view, ViewSettings{});
  surround.draw(timeS);
  Pictures pictures;
  pictures.rendered = surround.collect().clone();
  const cv::Mat positions = surround.panoramaPositions(timeS);
  const processing::PanoramaLut viewLut = processing::composeViewLut(rig.lut, positions, rig.pool);
  EXPECT_EQ(viewLut.size, positions.size());
  processing::Stitcher(viewLut, rig.pool).stitch(rig.images, pictures.direct);
  rig.correct(correction, viewLut, positions, pictures.direct);
  pictures.panoramaShown = SurroundView::panoramaShown(positions);
  pictures.rendered.copyTo(pictures.direct, ~pictures.panoramaShown);
  return pictures;
}

// With each colour correction: the view's picture corrected through the view (the field sampled
// where each pixel samples the panorama, the gains by the view LUT's cameras) against the render
// of the corrected panorama; and what each correction changes in the view, both ways. One camera
// is set a quarter darker than the rest, so that each correction has something to do.
TEST_F(ViewLutTest, EachFixedViewMatchesTheRenderer) {
  struct Case {
    ViewKind view;
    double timeS;
  };
  // The orbit at two poses: behind the vehicle (its start) and an eighth of a turn on, looking
  // across a seam.
  const std::vector<Case> cases{{ViewKind::kTop, 0},
                                {ViewKind::kPanorama360, 0},
                                {ViewKind::kOrbit, 0},
                                {ViewKind::kOrbit, 2.5},
                                {ViewKind::kRear, 0}};
  struct Panorama {
    const char* name;
    RigScene* rig;
    double minimumPsnr;
  };
  for (const auto& [name, scene, minimumPsnr] :
       {Panorama{"the rig's", rig.get(), 36.0}, Panorama{"a finer", fineRig.get(), 40.0}}) {
    std::vector<Pictures> uncorrected;
    for (const Correction correction : {Correction::kNone, Correction::kPoissonMultiplicative,
                                        Correction::kPoissonAdditive, Correction::kGain}) {
      scene->show(correction);
      for (std::size_t k = 0; k < cases.size(); ++k) {
        const auto [view, timeS] = cases[k];
        SCOPED_TRACE(::testing::Message() << toString(view) << " at " << timeS << " s, " << name
                                          << " panorama, " << nameOf(correction));
        const Pictures pictures = drawBoth(*scene, view, timeS, correction);
        // Most of each view is panorama, so the comparison covers it.
        EXPECT_GT(cv::countNonZero(pictures.panoramaShown), pictures.panoramaShown.total() / 2);
        EXPECT_GE(maskedPsnr(pictures.rendered, pictures.direct, pictures.panoramaShown),
                  minimumPsnr);
        if (correction == Correction::kNone) {
          uncorrected.push_back(pictures);
          continue;
        }
        // What the correction changed: levels, per pixel and channel.
        const auto change = [&](const cv::Mat& corrected, const cv::Mat& before) {
          cv::Mat difference;
          cv::subtract(corrected, before, difference, cv::noArray(), CV_16S);
          return difference;
        };
        const cv::Mat renderedChange = change(pictures.rendered, uncorrected[k].rendered);
        const cv::Mat directChange = change(pictures.direct, uncorrected[k].direct);
        const cv::Scalar size = cv::mean(cv::abs(renderedChange), pictures.panoramaShown);
        const cv::Scalar miss =
            cv::mean(cv::abs(directChange - renderedChange), pictures.panoramaShown);
        const double changed = (size[0] + size[1] + size[2]) / 3;
        const double missed = (miss[0] + miss[1] + miss[2]) / 3;
        EXPECT_GT(changed, 1.0);
        EXPECT_LT(missed, 0.1 * changed) << "changed " << changed << " levels on average";
      }
    }
  }
}

// With orbit_period_s 0 the orbit's eye stays where it starts: the picture of the moving orbit
// at that azimuth, at any stream time. Only the moving orbit and split views move.
TEST_F(ViewLutTest, AStillOrbitHoldsItsStartingPose) {
  ViewSettings cutting;  // views switched at once, for what moves() says of each
  cutting.transitionS = 0;
  ViewSettings still = cutting;
  still.orbitPeriodS = 0;
  still.orbitStartDeg = 225;  // the moving orbit's eye 2.5 s into its 20 s turn
  SurroundView moving(rig->scene, {640, 360}, ViewKind::kOrbit, cutting);
  SurroundView held(rig->scene, {640, 360}, ViewKind::kOrbit, still);
  rig->show(Correction::kNone);
  moving.draw(2.5);
  const cv::Mat expected = moving.collect().clone();
  for (const double timeS : {0.0, 7.0, 1000.0}) {
    held.draw(timeS);
    EXPECT_GE(cv::PSNR(expected, held.collect()), 50.0) << timeS << " s";
  }
  moving.draw(0);
  EXPECT_LT(cv::PSNR(expected, moving.collect()), 30.0);  // the moving one did move

  EXPECT_TRUE(moving.moves());
  EXPECT_FALSE(held.moves());
  moving.setView(ViewKind::kSplit);
  held.setView(ViewKind::kSplit);
  EXPECT_TRUE(moving.moves());
  EXPECT_FALSE(held.moves());
  for (const ViewKind view : {ViewKind::kTop, ViewKind::kPanorama360}) {
    moving.setView(view);
    EXPECT_FALSE(moving.moves()) << toString(view);
    EXPECT_FALSE(moving.cameraArea()) << toString(view);
  }
  // As large as fits in the right half, of the camera's shape.
  const cv::Rect area = *held.cameraArea();
  const cv::Size camera = rig->lut.cameraSizes.front();
  EXPECT_EQ(area & cv::Rect(320, 0, 320, 360), area);
  EXPECT_TRUE(area.width == 320 || area.height == 360) << area;
  EXPECT_NEAR(static_cast<double>(area.width) / area.height,
              static_cast<double>(camera.width) / camera.height, 0.02);
}

// A view being switched to is mapped, and drawn alone, as it shows once the switch has ended (the
// daemon sets its table up from the switch's first set on), each into a target of its own: the
// picture of the switch pending in the view is the one collected.
TEST_F(ViewLutTest, AViewIsMappedWhereASwitchGoesAndItsPendingPictureStays) {
  rig->show(Correction::kNone);
  const ViewSettings settings;  // a switch moves the eye over transitionS
  SurroundView settled(rig->scene, {640, 360}, ViewKind::kTop, settings);
  settled.draw(0);
  const cv::Mat top = settled.collect().clone();
  const cv::Mat topPositions = settled.panoramaPositions(0);

  SurroundView twin(rig->scene, {640, 360}, ViewKind::kOrbit, settings);
  SurroundView switching(rig->scene, {640, 360}, ViewKind::kOrbit, settings);
  for (SurroundView* view : {&twin, &switching}) {
    view->setView(ViewKind::kTop);
    view->draw(1.0);  // the switch starts
    (void)view->collect();
    view->draw(1.0 + settings.transitionS / 2);
  }
  ASSERT_TRUE(switching.moves());
  ASSERT_TRUE(switching.settlesStill());
  const cv::Mat still = switching.stillPicture(0);
  const cv::Mat positions = switching.panoramaPositions(0);
  EXPECT_EQ(cv::norm(still, top, cv::NORM_INF), 0);
  ASSERT_EQ(positions.size(), topPositions.size());
  ASSERT_EQ(positions.type(), topPositions.type());
  EXPECT_EQ(
      std::memcmp(positions.data, topPositions.data, positions.total() * positions.elemSize()), 0);
  const cv::Mat halfway = twin.collect().clone();
  EXPECT_EQ(cv::norm(switching.collect(), halfway, cv::NORM_INF), 0);
  EXPECT_LT(cv::PSNR(halfway, top), 30.0);  // the switch's picture, not the top view's
}

// The split view's camera half is a live picture, so it shows no panorama; its surround half does.
TEST_F(ViewLutTest, SplitViewMapsOnlyItsSurroundHalf) {
  SurroundView surround(rig->scene, {640, 360}, ViewKind::kSplit, ViewSettings{});
  const cv::Mat positions = surround.panoramaPositions(0);
  const cv::Mat shown = SurroundView::panoramaShown(positions);
  EXPECT_EQ(cv::countNonZero(shown.colRange(320, 640)), 0);
  EXPECT_GT(cv::countNonZero(shown.colRange(0, 320)), 320 * 360 / 2);
}

// Where the top view shows a ground point (on the bowl's floor, 5 m around), it samples the
// panorama pixel that looks at it.
TEST_F(ViewLutTest, TopViewSamplesThePanoramaWhereItsGroundIs) {
  const cv::Size size(640, 360);
  SurroundView surround(rig->scene, size, ViewKind::kTop, ViewSettings{});
  const cv::Mat positions = surround.panoramaPositions(0);
  const processing::PanoramaGeometry& panorama = rig->settings.geometry;
  const double pixelsPerMetre = size.height / (2 * ViewSettings{}.topRangeM);
  for (const cv::Point2d ground :
       {cv::Point2d(4, 1), cv::Point2d(-3, -3), cv::Point2d(1.5, -4.5)}) {
    // Front up, left on the left: x along rows upwards, y along columns leftwards.
    const cv::Point at(static_cast<int>(size.width / 2.0 - ground.y * pixelsPerMetre),
                       static_cast<int>(size.height / 2.0 - ground.x * pixelsPerMetre));
    const cv::Point2d centreOfPixel(size.width / 2.0 - at.x - 0.5, size.height / 2.0 - at.y - 0.5);
    const cv::Vec3d seen(centreOfPixel.y / pixelsPerMetre, centreOfPixel.x / pixelsPerMetre, 0);
    const cv::Point2d wanted = panorama.pixel(seen - panorama.centre);
    const auto& sampled = positions.at<cv::Vec2f>(at);
    double dc = std::abs(sampled[0] - wanted.x);
    dc = std::min(dc, panorama.size.width - dc);
    EXPECT_LT(std::hypot(dc, sampled[1] - wanted.y), 1.0)
        << "ground point " << ground << " at " << at << ": samples (" << sampled[0] << ", "
        << sampled[1] << "), wanted " << wanted;
  }
}

}  // namespace
}  // namespace surroundd::render
