// The surround view shown in an X window through EGL, on an Xvfb server of the suite's own and
// Mesa's EGL on it: what the window shows, read from the screen by a second client, is exactly the
// view's read-back picture; closing the window or losing the server stops the window while the
// renderer goes on drawing; a renderer off the X server, a view of another size and a missing
// display are named.

#include "render/outputs/egl_window_sink.hpp"

#include <memory>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "processing/surround_mesh.hpp"
#include "render/render_error.hpp"
#include "render/surround_scene.hpp"
#include "render/surround_view.hpp"
#include "tests/support/test_support.hpp"
#include "tests/support/x11_test_server.hpp"

// After every other header: Xlib's macros.
#include "render/outputs/xlib_display.hpp"

namespace surroundd::render {
namespace {

using ::testing::HasSubstr;

// Even (as views are), and not a multiple of 4, so that a row stride would show.
constexpr int kWidth = 322;
constexpr int kHeight = 202;
cv::Size viewSize() { return {kWidth, kHeight}; }

X11WindowSettings windowSettings(const std::string& display) {
  return {.display = display, .title = "surroundd EGL test", .size = viewSize()};
}

// A renderer on its own X server: the connection, the context on it, and an orbit view of a
// synthetic panorama (the eye moves with time, so two pictures differ).
class EglRenderer {
 public:
  EglRenderer()
      : display_(std::make_unique<XlibDisplay>(server_.display())),
        gl_(std::make_unique<EglContext>(EglPlatform::kX11, display_->get())),
        scene_(std::make_unique<SurroundScene>(
            processing::buildSurroundMesh(processing::MeshSettings{},
                                          processing::PanoramaGeometry{}),
            processing::PanoramaGeometry{}, processing::VehicleDimensions{}, cv::Size{320, 180})),
        view_(
            std::make_unique<SurroundView>(*scene_, viewSize(), ViewKind::kOrbit, ViewSettings{})) {
    scene_->uploadPanorama(testing::syntheticPicture(processing::PanoramaGeometry{}.size, 5));
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
  // The view at `timeS`, drawn and shown by `sink`, not read back; on the screen when this
  // returns (the swap's requests go through the renderer's connection).
  void show(EglWindowSink& sink, double timeS) {
    view_->draw(timeS, SurroundView::ReadBack::kNo);
    sink.present(*view_, std::chrono::duration_cast<std::chrono::nanoseconds>(
                             std::chrono::duration<double>(timeS)));
    EXPECT_FALSE(view_->pending());
    display_->sync("waiting for the picture");
  }
  X11WindowSettings windowSettings() const { return render::windowSettings(server_.display()); }

  testing::XvfbServer server_;
  std::unique_ptr<XlibDisplay> display_;
  std::unique_ptr<EglContext> gl_;
  std::unique_ptr<SurroundScene> scene_;
  std::unique_ptr<SurroundView> view_;
};

double maxDifference(const cv::Mat& a, const cv::Mat& b) { return cv::norm(a, b, cv::NORM_INF); }

TEST(EglWindowSink, ShowsTheViewAsItsReadBackPictureIs) {
  EglRenderer renderer;
  const testing::X11Observer observer(renderer.server_.display());
  EglWindowSink sink(*renderer.gl_, renderer.windowSettings());
  EXPECT_TRUE(sink.presentsViews());
  EXPECT_TRUE(sink.wantsFrame(std::chrono::nanoseconds(0)));
  EXPECT_EQ(observer.title(sink.windowId()), "surroundd EGL test");

  const cv::Mat first = renderer.draw(0.0);
  renderer.show(sink, 0.0);
  EXPECT_EQ(maxDifference(observer.contents(sink.windowId()), first), 0);

  const cv::Mat second = renderer.draw(2.5);
  ASSERT_GT(maxDifference(first, second), 100) << "the orbiting eye moved";
  renderer.show(sink, 2.5);
  EXPECT_EQ(maxDifference(observer.contents(sink.windowId()), second), 0);
  EXPECT_EQ(sink.framesShown(), 2U);
  EXPECT_THAT(sink.describe(), HasSubstr("(2 frames)"));
}

TEST(EglWindowSink, StopsWhenTheUserClosesItAndTheRendererGoesOn) {
  EglRenderer renderer;
  const testing::X11Observer observer(renderer.server_.display());
  EglWindowSink sink(*renderer.gl_, renderer.windowSettings());
  const cv::Mat picture = renderer.draw(1.0);
  renderer.show(sink, 1.0);
  const unsigned long id = sink.windowId();

  observer.sendDeleteWindow(id);
  EXPECT_FALSE(sink.wantsFrame(std::chrono::nanoseconds(0)));
  EXPECT_FALSE(observer.exists(id));
  renderer.show(sink, 1.0);
  EXPECT_THAT(sink.describe(), HasSubstr("(1 frames; closed by the user)"));
  EXPECT_EQ(maxDifference(renderer.draw(1.0), picture), 0);
}

TEST(EglWindowSink, StopsWhenTheServerGoesAwayAndTheRendererGoesOn) {
  EglRenderer renderer;
  EglWindowSink sink(*renderer.gl_, renderer.windowSettings());
  const cv::Mat picture = renderer.draw(1.0);
  renderer.show(sink, 1.0);

  renderer.server_.stop();
  renderer.show(sink, 1.0);
  EXPECT_FALSE(sink.wantsFrame(std::chrono::nanoseconds(0)));
  EXPECT_EQ(sink.windowId(), 0U);
  EXPECT_THAT(sink.describe(), HasSubstr("(1 frames; the display went away)"));
  // The context draws into its framebuffers without the server.
  EXPECT_EQ(maxDifference(renderer.draw(1.0), picture), 0);
}

TEST(EglWindowSink, RefusesAViewOfAnotherSizeAndPictures) {
  EglRenderer renderer;
  EglWindowSink sink(*renderer.gl_, renderer.windowSettings());
  const SurroundView other(*renderer.scene_, {320, 200}, ViewKind::kTop, ViewSettings{});
  EXPECT_THAT(
      [&] { sink.present(other, std::chrono::nanoseconds(0)); },
      ::testing::ThrowsMessage<RenderError>(HasSubstr("the view is 320x200, the window 322x202")));
  EXPECT_THAT([&] { sink.consume(renderer.draw(0), std::chrono::nanoseconds(0)); },
              ::testing::ThrowsMessage<RenderError>(HasSubstr("not pictures")));
}

TEST(EglWindowSink, NeedsTheRenderersContextOnTheXServer) {
  const testing::XvfbServer server;
  EglContext headless(EglPlatform::kSurfaceless);
  EXPECT_THAT([&] { const EglWindowSink sink(headless, windowSettings(server.display())); },
              ::testing::ThrowsMessage<RenderError>(
                  HasSubstr("the renderer's context is on the surfaceless platform, not on an X "
                            "server's")));
  EXPECT_THAT([] { const EglContext gl(EglPlatform::kX11); },
              ::testing::ThrowsMessage<RenderError>(HasSubstr("x11: no X display given")));
}

}  // namespace
}  // namespace surroundd::render
