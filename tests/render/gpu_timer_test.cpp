// The GPU's own time of a step (render/gpu_timer.hpp), on whatever EGL gives (llvmpipe here): each
// run's time comes back once the GPU has done it, per step, oldest first; reading never waits; a
// step whose queries are all unread goes untimed rather than waiting; scopes of a null timer do
// nothing. Skipped, with a message, where the driver has no GL_EXT_disjoint_timer_query.

#include "render/gpu_timer.hpp"

#include <algorithm>
#include <chrono>
#include <vector>

#include <gtest/gtest.h>

#include "render/egl_context.hpp"
#include "render/gl_objects.hpp"

namespace surroundd::render {
namespace {

using std::chrono::nanoseconds;

class GpuTimerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!timer_.available()) GTEST_SKIP() << "the renderer has no GL_EXT_disjoint_timer_query";
    glBindRenderbuffer(GL_RENDERBUFFER, colour_.name());
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, kSide, kSide);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.name());
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                              colour_.name());
    glBindBuffer(GL_PIXEL_PACK_BUFFER, readBuffer_.name());
    glBufferData(GL_PIXEL_PACK_BUFFER, GLsizeiptr{kSide} * kSide * 4, nullptr, GL_STREAM_READ);
    // A first run, read and set aside: llvmpipe misreads a context's first query (see the header).
    run(GpuStep::kUpload);
    glFinish();
    (void)timer_.collect();
  }
  void TearDown() override {
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }

  // A run of `step` that the GPU has work in: a clear of the framebuffer and its read-back.
  void run(GpuStep step) {
    const GpuTimer::Scope timed(&timer_, step);
    glClearColor(0.2F, 0.4F, 0.6F, 1.0F);
    glClear(GL_COLOR_BUFFER_BIT);
    glReadPixels(0, 0, kSide, kSide, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  }
  // The readings of the runs finished by now, after waiting for the GPU.
  std::vector<GpuTimer::Reading> finished() {
    glFinish();
    const auto readings = timer_.collect();
    return {readings.begin(), readings.end()};
  }

  static constexpr int kSide = 512;
  EglContext context_;
  GpuTimer timer_;
  gl::Renderbuffer colour_;
  gl::Framebuffer framebuffer_;
  gl::Buffer readBuffer_;
};

TEST_F(GpuTimerTest, EachRunsTimeComesBackOnceDoneUnderItsStep) {
  run(GpuStep::kDraw);
  run(GpuStep::kReadBack);
  run(GpuStep::kDraw);
  const auto readings = finished();
  ASSERT_EQ(readings.size(), 3u);
  // Per step in the steps' order, each step's oldest first.
  EXPECT_EQ(readings[0].step, GpuStep::kDraw);
  EXPECT_EQ(readings[1].step, GpuStep::kDraw);
  EXPECT_EQ(readings[2].step, GpuStep::kReadBack);
  for (const auto& reading : readings) {
    EXPECT_GT(reading.time, nanoseconds(0)) << toString(reading.step);
    EXPECT_LT(reading.time, std::chrono::seconds(1)) << toString(reading.step);
  }
  // Read once: the next collect has nothing new.
  EXPECT_TRUE(finished().empty());
  EXPECT_EQ(timer_.untimed(), 0u);
}

TEST_F(GpuTimerTest, AStepWhoseQueriesAreAllUnreadGoesUntimedInsteadOfWaiting) {
  constexpr std::size_t kRuns = GpuTimer::kQueriesPerStep + 3;
  for (std::size_t i = 0; i < kRuns; ++i) run(GpuStep::kStitch);
  EXPECT_EQ(timer_.untimed(), 3u);
  EXPECT_EQ(finished().size(), GpuTimer::kQueriesPerStep);
  // Read, its queries serve again.
  run(GpuStep::kStitch);
  EXPECT_EQ(finished().size(), 1u);
  EXPECT_EQ(timer_.untimed(), 3u);
}

TEST_F(GpuTimerTest, ARunNotDoneWhenReadComesWithALaterRead) {
  // Reading right after the calls does not wait: what is not done yet comes with a later read.
  std::size_t read = 0;
  for (int i = 0; i < 4; ++i) {
    run(GpuStep::kDraw);
    read += timer_.collect().size();
  }
  read += finished().size();
  EXPECT_EQ(read, 4u);
}

TEST(GpuTimerScope, WithoutATimerTimesNothing) {
  const EglContext context;
  { const GpuTimer::Scope timed(nullptr, GpuStep::kDraw); }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(GpuStepNames, AreTheReportsWords) {
  EXPECT_STREQ(toString(GpuStep::kUpload), "upload");
  EXPECT_STREQ(toString(GpuStep::kStitch), "stitch");
  EXPECT_STREQ(toString(GpuStep::kDraw), "draw");
  EXPECT_STREQ(toString(GpuStep::kReadBack), "read-back");
}

}  // namespace
}  // namespace surroundd::render
