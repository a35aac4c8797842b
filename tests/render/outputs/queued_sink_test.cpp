// The encoder queue: every picture in order when it waits, the newest winning when it drops, and a
// failure of the output reaching the pipeline thread.

#include "render/outputs/queued_sink.hpp"

#include <chrono>
#include <future>
#include <latch>
#include <mutex>
#include <stdexcept>
#include <utility>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "tests/support/test_support.hpp"

namespace surroundd::render {
namespace {

using std::chrono::milliseconds;
using WhenFull = QueuedSink::WhenFull;

// NOLINTNEXTLINE(cert-err58-cpp): cv::Size stores two ints; its constructor throws nothing.
const cv::Size kSize(64, 48);

cv::Mat picture(int index) { return testing::syntheticPicture(kSize, index); }

// An output that keeps what it is given, and can be held (like an encoder stuck on a slow disk)
// or made to fail.
class KeepingSink final : public FrameSink {
 public:
  struct Shared {
    std::mutex mutex;
    std::vector<std::pair<cv::Mat, std::chrono::nanoseconds>> consumed;
    std::latch release{1};
    bool hold = false;
    std::promise<void> holding;  // set when the first held picture is taken
    bool holdingSet = false;     // only the worker thread touches it
    int failAt = -1;
    bool finished = false;
    bool takesI420 = false;
  };
  explicit KeepingSink(Shared& shared) : shared_(shared) {}
  void consume(const cv::Mat& bgr, const PictureTime& time) override {
    if (shared_.hold) {
      if (!std::exchange(shared_.holdingSet, true)) shared_.holding.set_value();
      shared_.release.wait();
    }
    const std::lock_guard lock(shared_.mutex);
    if (static_cast<int>(shared_.consumed.size()) == shared_.failAt) {
      throw std::runtime_error("disk full");
    }
    shared_.consumed.emplace_back(bgr.clone(), time.stream);
  }
  void finish(const cv::Mat& /*lastFrame*/, std::chrono::nanoseconds /*lastTime*/) override {
    shared_.finished = true;
  }
  std::string describe() const override { return "kept"; }
  bool takesI420() const override { return shared_.takesI420; }

 private:
  Shared& shared_;
};

TEST(QueuedSink, WhenItWaitsEveryPictureArrivesInOrder) {
  KeepingSink::Shared shared;
  QueuedSink sink(std::make_unique<KeepingSink>(shared), kSize, 2, WhenFull::kWait);
  for (int i = 0; i < 20; ++i) sink.consume(picture(i), milliseconds(i));
  sink.finish({}, {});
  EXPECT_TRUE(shared.finished);
  ASSERT_EQ(shared.consumed.size(), 20u);
  for (int i = 0; i < 20; ++i) {
    EXPECT_EQ(shared.consumed[i].second, milliseconds(i));
    EXPECT_EQ(cv::norm(shared.consumed[i].first, picture(i), cv::NORM_INF), 0.0) << i;
  }
  EXPECT_EQ(sink.dropped(), 0u);
  EXPECT_EQ(sink.describe(), "kept");
}

// For an encoder that takes I420: its slots hold that, and a picture drawn in BGR (a view that
// moves) still comes through as it was given, each in turn.
TEST(QueuedSink, ASinkThatTakesI420GetsEachPictureInTheFormatItCameIn) {
  KeepingSink::Shared shared;
  shared.takesI420 = true;
  QueuedSink sink(std::make_unique<KeepingSink>(shared), kSize, 2, WhenFull::kWait);
  EXPECT_TRUE(sink.takesI420());
  std::vector<cv::Mat> given;
  for (int i = 0; i < 12; ++i) {
    cv::Mat& next = given.emplace_back();
    if (i % 4 < 2) {
      cv::cvtColor(picture(i), next, cv::COLOR_BGR2YUV_I420);
    } else {
      next = picture(i);
    }
    sink.consume(next, milliseconds(i));
  }
  sink.finish({}, {});
  ASSERT_EQ(shared.consumed.size(), given.size());
  for (std::size_t i = 0; i < given.size(); ++i) {
    const cv::Mat& consumed = shared.consumed[i].first;
    ASSERT_EQ(consumed.type(), given[i].type()) << i;
    ASSERT_EQ(consumed.size(), given[i].size()) << i;
    EXPECT_EQ(cv::norm(consumed, given[i], cv::NORM_INF), 0.0) << i;
  }
  EXPECT_TRUE(isI420(shared.consumed[0].first, kSize));
}

TEST(QueuedSink, WhenItDropsTheNewestPicturesWinAndDropsAreCounted) {
  KeepingSink::Shared shared;
  shared.hold = true;
  QueuedSink sink(std::make_unique<KeepingSink>(shared), kSize, 3, WhenFull::kDropOldest);
  sink.consume(picture(0), milliseconds(0));
  // The worker has taken the first picture and is stuck on it (bounded: a worker that never takes
  // it fails the test instead of hanging it).
  const bool taken =
      shared.holding.get_future().wait_for(std::chrono::seconds(30)) == std::future_status::ready;
  if (!taken) shared.release.count_down();
  ASSERT_TRUE(taken);
  for (int i = 1; i < 10; ++i) sink.consume(picture(i), milliseconds(i));  // never blocks
  shared.release.count_down();
  sink.finish({}, {});
  ASSERT_EQ(shared.consumed.size(), 4u);
  EXPECT_EQ(shared.consumed[0].second, milliseconds(0));
  for (int k = 1; k < 4; ++k) {
    EXPECT_EQ(shared.consumed[k].second, milliseconds(6 + k));
    EXPECT_EQ(cv::norm(shared.consumed[k].first, picture(6 + k), cv::NORM_INF), 0.0);
  }
  EXPECT_EQ(sink.dropped(), 6u);
  EXPECT_EQ(sink.describe(), "kept; 6 pictures dropped (output too slow)");
}

TEST(QueuedSink, AFailureOfTheOutputIsRethrownOnThePipelineThread) {
  KeepingSink::Shared shared;
  shared.failAt = 2;
  QueuedSink sink(std::make_unique<KeepingSink>(shared), kSize, 1, WhenFull::kWait);
  EXPECT_THROW(
      {
        for (int i = 0; i < 10; ++i) sink.consume(picture(i), milliseconds(i));
        sink.finish({}, {});
      },
      std::runtime_error);
  EXPECT_FALSE(shared.finished);
  EXPECT_EQ(shared.consumed.size(), 2u);
}

}  // namespace
}  // namespace surroundd::render
