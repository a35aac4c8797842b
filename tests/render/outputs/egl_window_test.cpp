// The surround view shown in an X window through EGL, on an Xvfb server of the suite's own and
// Mesa's EGL on it: what the window shows, read from the screen by a second client, is exactly the
// view's read-back picture; closing the window or losing the server stops the window while the
// renderer goes on drawing; a renderer off the X server, a view of another size and a missing
// display are named.

#include "render/outputs/egl_window.hpp"

#include <memory>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "processing/surround_mesh.hpp"
#include "render/outputs/xlib_display.hpp"  // after every other header: Xlib's macros
#include "render/render_error.hpp"
#include "tests/support/test_support.hpp"
#include "tests/support/x11_test_server.hpp"

namespace surroundd::render {
namespace {

using ::testing::HasSubstr;

// Even (as views are), and not a multiple of 4, so that a row stride would show.
constexpr int kWidth = 322;
constexpr int kHeight = 202;
cv::Size viewSize() { return {kWidth, kHeight}; }

processing::PanoramaGeometry testPanorama() {
  processing::PanoramaGeometry geometry;
  geometry.size = {1024, 512};
  geometry.centre = {0, 0, 1.9};
  return geometry;
}

ViewSettings cutting() {
  ViewSettings settings;
  settings.transitionS = 0;
  return settings;
}

// The display is the renderer's connection's.
X11WindowSettings windowSettings() {
  return {.display = "", .title = "surroundd EGL test", .size = viewSize()};
}

// A renderer on its own X server: the connection, the context on it, and an orbit view of a
// synthetic panorama (the eye moves with time, so two pictures differ).
class EglRenderer {
 public:
  EglRenderer()
      : display_(std::make_unique<XlibDisplay>(server_.display())),
        gl_(std::make_unique<EglContext>(EglPlatform::kX11, display_->get())),
        scene_(std::make_unique<SurroundScene>(
            processing::buildSurroundMesh(processing::MeshSettings{}, testPanorama()),
            testPanorama(), CarDimensions{}, cv::Size{320, 180})),
        view_(std::make_unique<SurroundView>(*scene_, viewSize(), ViewKind::kOrbit, cutting())) {
    scene_->uploadPanorama(testing::syntheticPicture(testPanorama().size, 5));
  }
  ~EglRenderer() {
    view_.reset();
    scene_.reset();
  }
  EglRenderer(const EglRenderer&) = delete;
  EglRenderer& operator=(const EglRenderer&) = delete;

  // The view at `timeS`, drawn; returns its read-back picture.
  cv::Mat draw(double timeS) {
    view_->draw(timeS);
    return view_->collect().clone();
  }

  testing::XvfbServer server_;
  std::unique_ptr<XlibDisplay> display_;
  std::unique_ptr<EglContext> gl_;
  std::unique_ptr<SurroundScene> scene_;
  std::unique_ptr<SurroundView> view_;
};

double maxDifference(const cv::Mat& a, const cv::Mat& b) { return cv::norm(a, b, cv::NORM_INF); }

TEST(EglWindow, ShowsTheViewAsItsReadBackPictureIs) {
  EglRenderer renderer;
  const testing::X11Observer observer(renderer.server_.display());
  EglWindow window(*renderer.gl_, *renderer.display_, windowSettings());
  ASSERT_TRUE(window.open());
  EXPECT_EQ(observer.title(window.windowId()), "surroundd EGL test");

  const cv::Mat first = renderer.draw(0.0);
  ASSERT_TRUE(window.present(*renderer.view_));
  EXPECT_EQ(maxDifference(observer.contents(window.windowId()), first), 0);

  const cv::Mat second = renderer.draw(2.5);
  ASSERT_GT(maxDifference(first, second), 100) << "the orbiting eye moved";
  ASSERT_TRUE(window.present(*renderer.view_));
  EXPECT_EQ(maxDifference(observer.contents(window.windowId()), second), 0);
  EXPECT_EQ(window.framesShown(), 2U);
  EXPECT_THAT(window.describe(), HasSubstr("(2 frames)"));
}

TEST(EglWindow, StopsWhenTheUserClosesItAndTheRendererGoesOn) {
  EglRenderer renderer;
  const testing::X11Observer observer(renderer.server_.display());
  EglWindow window(*renderer.gl_, *renderer.display_, windowSettings());
  const cv::Mat picture = renderer.draw(1.0);
  ASSERT_TRUE(window.present(*renderer.view_));
  const unsigned long id = window.windowId();

  observer.sendDeleteWindow(id);
  EXPECT_FALSE(window.present(*renderer.view_));
  EXPECT_FALSE(window.open());
  EXPECT_FALSE(observer.exists(id));
  EXPECT_THAT(window.describe(), HasSubstr("(1 frames; closed by the user)"));
  EXPECT_EQ(maxDifference(renderer.draw(1.0), picture), 0);
}

TEST(EglWindow, StopsWhenTheServerGoesAwayAndTheRendererGoesOn) {
  EglRenderer renderer;
  EglWindow window(*renderer.gl_, *renderer.display_, windowSettings());
  const cv::Mat picture = renderer.draw(1.0);
  ASSERT_TRUE(window.present(*renderer.view_));

  renderer.server_.stop();
  EXPECT_FALSE(window.present(*renderer.view_));
  EXPECT_EQ(window.windowId(), 0U);
  EXPECT_THAT(window.describe(), HasSubstr("(1 frames; the display went away)"));
  // The context draws into its framebuffers without the server.
  EXPECT_EQ(maxDifference(renderer.draw(1.0), picture), 0);
  EXPECT_FALSE(window.present(*renderer.view_));
}

TEST(EglWindow, RefusesAViewOfAnotherSize) {
  EglRenderer renderer;
  EglWindow window(*renderer.gl_, *renderer.display_, windowSettings());
  const SurroundView other(*renderer.scene_, {320, 200}, ViewKind::kTop, cutting());
  EXPECT_THAT(
      [&] { window.present(other); },
      ::testing::ThrowsMessage<RenderError>(HasSubstr("the view is 320x200, the window 322x202")));
}

TEST(EglWindow, NeedsTheRenderersContextOnTheXServer) {
  const testing::XvfbServer server;
  XlibDisplay display(server.display());
  const EglContext headless(EglPlatform::kSurfaceless);
  EXPECT_THAT(
      [&] { EglWindow window(const_cast<EglContext&>(headless), display, windowSettings()); },
      ::testing::ThrowsMessage<RenderError>(
          HasSubstr("the renderer's context is on the surfaceless platform, not on the X "
                    "server's")));
  EXPECT_THAT([] { EglContext gl(EglPlatform::kX11); },
              ::testing::ThrowsMessage<RenderError>(HasSubstr("x11: no X display given")));
}

}  // namespace
}  // namespace surroundd::render
