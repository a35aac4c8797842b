// The X11 window output, on an Xvfb server of the suite's own: what the window shows is read back
// from the screen by a second client, exactly; closing the window or losing the server stops the
// sink without an error; bad displays and bad frames are named.

#include "render/outputs/x11_window_sink.hpp"

#include <csignal>
#include <filesystem>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "render/render_error.hpp"
#include "tests/support/test_support.hpp"
#include "tests/support/x11_test_server.hpp"

namespace surroundd::render {
namespace {

using std::chrono::milliseconds;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// Odd sizes, so that a row stride or an off-by-one column would show.
constexpr int kWidth = 321;
constexpr int kHeight = 203;

// Gradients, hard edges and shapes that move with `index`.
cv::Mat testPicture(int index) { return testing::syntheticPicture({kWidth, kHeight}, index); }

// The largest difference of any channel of any pixel.
double maxDifference(const cv::Mat& a, const cv::Mat& b) { return cv::norm(a, b, cv::NORM_INF); }

// Calls `done` until it is true or 5 s have passed; returns its last answer.
template <typename Done>
bool pollUntil(Done done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(milliseconds(1));
  }
  return true;
}

class X11WindowSinkTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { sharedServer = std::make_unique<testing::XvfbServer>(); }
  static void TearDownTestSuite() { sharedServer.reset(); }
  void SetUp() override {
    ASSERT_NE(sharedServer, nullptr) << "Xvfb did not start";
    observer_ = std::make_unique<testing::X11Observer>(sharedServer->display());
  }

  static X11WindowSettings settings(const std::string& display) {
    return {.display = display, .title = "surroundd test", .size = {kWidth, kHeight}};
  }

  // One server for the suite; tests that stop or configure a server start their own.
  inline static std::unique_ptr<testing::XvfbServer> sharedServer;
  std::unique_ptr<testing::X11Observer> observer_;
};

TEST_F(X11WindowSinkTest, ShowsEachFrameExactly) {
  X11WindowSink sink(settings(sharedServer->display()));
  EXPECT_TRUE(sink.wantsFrame(milliseconds(0)));
  EXPECT_TRUE(sink.sharedMemory()) << "a local Xvfb offers MIT-SHM";
  EXPECT_EQ(observer_->title(sink.windowId()), "surroundd test");

  const cv::Mat first = testPicture(0);
  sink.consume(first, milliseconds(0));
  EXPECT_LE(maxDifference(observer_->contents(sink.windowId()), first), 1);

  const cv::Mat second = testPicture(40);
  sink.consume(second, milliseconds(33));
  const cv::Mat shown = observer_->contents(sink.windowId());
  EXPECT_LE(maxDifference(shown, second), 1);
  EXPECT_GT(maxDifference(shown, first), 100) << "the two pictures differ, so must the window";

  sink.finish(second, milliseconds(33));
  EXPECT_TRUE(observer_->exists(sink.windowId())) << "the window stays until the sink goes";
  EXPECT_EQ(sink.framesShown(), 2U);
  EXPECT_EQ(sink.describe(), "window on " + sharedServer->display() + " (2 frames)");
}

TEST_F(X11WindowSinkTest, ShowsFramesWithoutMitShm) {
  testing::XvfbServer server({"-extension", "MIT-SHM"});
  const testing::X11Observer observer(server.display());
  X11WindowSink sink(settings(server.display()));
  EXPECT_FALSE(sink.sharedMemory());

  const cv::Mat picture = testPicture(7);
  sink.consume(picture, milliseconds(0));
  EXPECT_LE(maxDifference(observer.contents(sink.windowId()), picture), 1);
}

TEST_F(X11WindowSinkTest, RedrawsTheLastFrameWhenUncovered) {
  X11WindowSink sink(settings(sharedServer->display()));
  const cv::Mat picture = testPicture(3);
  sink.consume(picture, milliseconds(0));

  observer_->cover(sink.windowId());
  ASSERT_GT(maxDifference(observer_->contents(sink.windowId()), picture), 100)
      << "the cover hides the picture";
  observer_->uncover();
  // The server paints the uncovered window black; the sink redraws it once it reads the Expose.
  EXPECT_TRUE(pollUntil([&] {
    sink.wantsFrame(milliseconds(0));
    return maxDifference(observer_->contents(sink.windowId()), picture) <= 1;
  }));
  EXPECT_EQ(sink.framesShown(), 1U);
}

TEST_F(X11WindowSinkTest, StopsWhenTheUserClosesTheWindow) {
  X11WindowSink sink(settings(sharedServer->display()));
  const cv::Mat picture = testPicture(0);
  sink.consume(picture, milliseconds(0));
  const unsigned long window = sink.windowId();

  observer_->sendDeleteWindow(window);
  EXPECT_TRUE(pollUntil([&] { return !sink.wantsFrame(milliseconds(33)); }));
  EXPECT_FALSE(observer_->exists(window));
  EXPECT_THAT(sink.describe(), HasSubstr("(1 frames; closed by the user)"));

  EXPECT_NO_THROW(sink.consume(picture, milliseconds(33)));
  EXPECT_EQ(sink.framesShown(), 1U);
}

TEST_F(X11WindowSinkTest, StopsWhenTheDisplayGoesAway) {
  // As the daemon does (daemon/main.cpp): writing to a server that is gone must fail, not kill.
  std::signal(SIGPIPE, SIG_IGN);
  testing::XvfbServer server;
  X11WindowSink sink(settings(server.display()));
  const cv::Mat picture = testPicture(0);
  sink.consume(picture, milliseconds(0));

  server.stop();
  EXPECT_NO_THROW(sink.consume(picture, milliseconds(33)));
  EXPECT_FALSE(sink.wantsFrame(milliseconds(66)));
  EXPECT_THAT(sink.describe(), HasSubstr("(1 frames; the display went away)"));
}

TEST_F(X11WindowSinkTest, NamesTheDisplayItCannotOpen) {
  ASSERT_FALSE(std::filesystem::exists("/tmp/.X11-unix/X59999"));
  auto bad = settings("unix:59999");
  EXPECT_THAT([&] { X11WindowSink sink(bad); },
              ThrowsMessage<RenderError>(HasSubstr("cannot open display 'unix:59999'")));
}

TEST_F(X11WindowSinkTest, RejectsFramesOfAnotherSizeOrType) {
  X11WindowSink sink(settings(sharedServer->display()));
  const cv::Mat large = testing::syntheticPicture({640, 480}, 0);
  EXPECT_THAT([&] { sink.consume(large, milliseconds(0)); },
              ThrowsMessage<RenderError>(AllOf(HasSubstr("640x480"), HasSubstr("321x203"))));
  const cv::Mat grey(kHeight, kWidth, CV_8UC1, cv::Scalar(128));
  EXPECT_THAT([&] { sink.consume(grey, milliseconds(0)); },
              ThrowsMessage<RenderError>(HasSubstr("8-bit BGR")));
  EXPECT_EQ(sink.framesShown(), 0U);

  auto empty = settings(sharedServer->display());
  empty.size = {};
  EXPECT_THAT([&] { X11WindowSink unsized(empty); },
              ThrowsMessage<RenderError>(HasSubstr("size must be positive, got 0x0")));
}

}  // namespace
}  // namespace surroundd::render
