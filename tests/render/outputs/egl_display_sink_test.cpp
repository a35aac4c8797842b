// The surround view shown on a KMS screen through EGL on the card's GBM device: on a screen the
// tests may take over (a virtual machine's: ctest's EglDisplaySink.OnAKmsScreen, through
// scripts/device-vm.sh), the frame buffer the screen scans out is exactly the view's read-back
// picture, between black bars, and flips with each view; a view smaller than the mode is scaled
// up to fill it; the screen is given back as it was found. Anywhere: a renderer that is not on a
// card is refused.

#include "render/outputs/egl_display_sink.hpp"

#include <memory>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "processing/surround_mesh.hpp"
#include "render/render_error.hpp"
#include "render/surround_scene.hpp"
#include "render/surround_view.hpp"
#include "tests/support/kms_scanout.hpp"
#include "tests/support/kms_screen_test.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::render {
namespace {

using ::testing::HasSubstr;

PictureTime at(double seconds) {
  return PictureTime(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(seconds)));
}

// The renderer on the card's GBM device, and an orbit view of a synthetic panorama (the eye moves
// with time, so two pictures differ).
class CardRenderer {
 public:
  CardRenderer(const std::filesystem::path& card, double viewScale)
      : card_(std::make_unique<DrmCard>(DrmDisplaySettings{card, ""})),
        gl_(std::make_unique<EglContext>(EglPlatform::kGbm, card_->gbm())),
        scene_(std::make_unique<SurroundScene>(
            processing::buildSurroundMesh(processing::MeshSettings{},
                                          processing::PanoramaGeometry{}),
            processing::PanoramaGeometry{}, processing::VehicleDimensions{}, cv::Size{320, 180})) {
    const cv::Size mode = KmsScreen(card_->fd(), card_->path(), "").size();
    // Even sizes, as views are.
    const cv::Size size(static_cast<int>(mode.width * viewScale) / 2 * 2,
                        static_cast<int>(mode.height * viewScale / 2) / 2 * 2);
    view_ = std::make_unique<SurroundView>(*scene_, size, ViewKind::kOrbit, ViewSettings{});
    scene_->uploadPanorama(testing::syntheticPicture(processing::PanoramaGeometry{}.size, 5));
  }
  ~CardRenderer() {
    view_.reset();
    scene_.reset();
  }
  CardRenderer(const CardRenderer&) = delete;
  CardRenderer& operator=(const CardRenderer&) = delete;

  // The view at `timeS`, drawn; its read-back picture.
  cv::Mat draw(double timeS) {
    view_->draw(timeS);
    return view_->collect().clone();
  }
  // The view at `timeS`, drawn with no read-back and shown by `sink`, on the screen when this
  // returns.
  void show(EglDisplaySink& sink, double timeS) {
    view_->draw(timeS, SurroundView::ReadBack::kNo);
    sink.present(*view_, at(timeS));
    sink.finish({}, at(timeS).stream);
  }

  std::unique_ptr<DrmCard> card_;
  std::unique_ptr<EglContext> gl_;
  std::unique_ptr<SurroundScene> scene_;
  std::unique_ptr<SurroundView> view_;
};

using EglDisplaySinkOnAScreen = testing::KmsScreenTest;

TEST_F(EglDisplaySinkOnAScreen, ShowsEachViewAsItsReadBackPictureIs) {
  CardRenderer renderer(card_, 1.0);  // as wide as the mode, half as high
  EglDisplaySink sink(*renderer.gl_, "");
  EXPECT_TRUE(sink.presentsViews());

  const cv::Mat first = renderer.draw(0.0);
  renderer.show(sink, 0.0);
  const auto mode = testing::scanout(card_).picture.size();
  const cv::Rect area = testing::fittedPlace(first.size(), mode);
  expectShown(first, area, 0);
  const std::uint32_t firstBuffer = testing::scanout(card_).framebuffer;

  const cv::Mat second = renderer.draw(2.5);
  ASSERT_GT(cv::norm(first, second, cv::NORM_INF), 100) << "the orbiting eye moved";
  renderer.show(sink, 2.5);
  expectShown(second, area, 0);
  EXPECT_NE(testing::scanout(card_).framebuffer, firstBuffer) << "no page flip";

  const cv::Mat third = renderer.draw(5.0);
  renderer.show(sink, 5.0);
  expectShown(third, area, 0);
  EXPECT_EQ(sink.framesShown(), 3U);
  EXPECT_THAT(sink.describe(),
              ::testing::MatchesRegex("EGL display .+-[0-9]+ [0-9]+x[0-9]+@[0-9]+ on "
                                      "/dev/dri/card[0-9]+ \\(3 frames\\)"));
}

TEST_F(EglDisplaySinkOnAScreen, ScalesASmallerViewUpToFillTheMode) {
  CardRenderer renderer(card_, 0.5);
  EglDisplaySink sink(*renderer.gl_, "");
  const cv::Mat picture = renderer.draw(1.0);
  renderer.show(sink, 1.0);
  const auto mode = testing::scanout(card_).picture.size();
  const cv::Rect area = testing::fittedPlace(picture.size(), mode);
  cv::Mat expected;
  cv::resize(picture, expected, area.size(), 0, 0, cv::INTER_LINEAR);
  // The GPU's bilinear filter against OpenCV's: the same samples, rounded apart.
  expectShown(expected, area, 2);
}

TEST_F(EglDisplaySinkOnAScreen, GivesTheScreenBackAsItFoundIt) {
  const auto before = testing::scanout(card_);
  {
    CardRenderer renderer(card_, 1.0);
    EglDisplaySink sink(*renderer.gl_, "");
    renderer.show(sink, 0.0);
    ASSERT_NE(testing::scanout(card_).framebuffer, before.framebuffer);
  }
  EXPECT_EQ(testing::scanout(card_).framebuffer, before.framebuffer);
}

TEST_F(EglDisplaySinkOnAScreen, PicturesOfOtherStreamsAreRefused) {
  CardRenderer renderer(card_, 1.0);
  EglDisplaySink sink(*renderer.gl_, "");
  EXPECT_THAT([&] { sink.consume(cv::Mat(8, 8, CV_8UC3), at(0)); },
              ::testing::ThrowsMessage<RenderError>(HasSubstr("not pictures of another stream")));
}

TEST(EglDisplaySink, ARendererThatIsNotOnACardIsRefused) {
  EglContext gl(EglPlatform::kSurfaceless);
  EXPECT_THAT([&] { EglDisplaySink sink(gl, ""); },
              ::testing::ThrowsMessage<RenderError>(
                  HasSubstr("the renderer's context is on the surfaceless platform, not on a "
                            "DRM card's GBM device")));
}

}  // namespace
}  // namespace surroundd::render
