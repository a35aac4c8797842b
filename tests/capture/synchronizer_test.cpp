// The synchronizer on timestamps alone: aligned cameras, jitter within tolerance, a camera that
// drops frames, one that starts late, one that ends, and timestamps that go backwards.

#include "capture/synchronizer.hpp"

#include <vector>

#include <gtest/gtest.h>

namespace surroundd::capture {
namespace {

using std::chrono::milliseconds;

class SynchronizerTest : public ::testing::Test {
 protected:
  FramePool pool_{64, cv::Size(4, 4)};

  FrameRef frameAt(double ms) {
    FrameRef frame = pool_.tryAcquire();
    frame->timestamp =
        std::chrono::duration_cast<Timestamp>(std::chrono::duration<double, std::milli>(ms));
    return frame;
  }

  // Feeds per-camera timestamp lists (ms) the way the pipeline does, ending each camera when its
  // list runs out; returns the emitted sets as lists of member timestamps (-1 for an empty slot).
  std::vector<std::vector<double>> run(Synchronizer& sync,
                                       const std::vector<std::vector<double>>& streams) {
    std::vector<std::size_t> next(streams.size(), 0);
    std::vector<std::vector<double>> sets;
    while (!sync.finished()) {
      for (std::size_t c = 0; c < streams.size(); ++c) {
        if (!sync.needs(c)) continue;
        if (next[c] < streams[c].size()) {
          sync.offer(c, frameAt(streams[c][next[c]++]));
        } else {
          sync.end(c);
        }
      }
      while (auto set = sync.pop()) {
        std::vector<double> members;
        for (std::size_t c = 0; c < set->cameraCount; ++c) {
          members.push_back(
              set->frame(c)
                  ? std::chrono::duration<double, std::milli>(set->frame(c)->timestamp).count()
                  : -1.0);
        }
        sets.push_back(members);
      }
    }
    return sets;
  }
};

TEST_F(SynchronizerTest, JitteredCamerasFormOneSetPerFrame) {
  Synchronizer sync(3, milliseconds(10));
  const auto sets = run(sync, {{0, 33, 67, 100}, {2, 35, 66, 101}, {4, 31, 69, 103}});
  ASSERT_EQ(sets.size(), 4u);
  EXPECT_EQ(sets[1], (std::vector<double>{33, 35, 31}));
  EXPECT_EQ(sync.stats().setsEmitted, 4u);
  EXPECT_EQ(sync.stats().totalDropped(), 0u);
  const std::chrono::duration<double, std::milli> spread = sync.stats().maxSpread;
  EXPECT_NEAR(spread.count(), 4.0, 1e-9);
}

TEST_F(SynchronizerTest, CameraThatDropsFramesCostsOnlyThoseSets) {
  // Camera 1 misses the frames at 33 and 100: the others' frames of those instants are dropped.
  Synchronizer sync(2, milliseconds(10));
  const auto sets = run(sync, {{0, 33, 67, 100, 133}, {1, 68, 134}});
  ASSERT_EQ(sets.size(), 3u);
  EXPECT_EQ(sets[0], (std::vector<double>{0, 1}));
  EXPECT_EQ(sets[1], (std::vector<double>{67, 68}));
  EXPECT_EQ(sets[2], (std::vector<double>{133, 134}));
  EXPECT_EQ(sync.stats().unmatchedDropped[0], 2u);
  EXPECT_EQ(sync.stats().unmatchedDropped[1], 0u);
}

TEST_F(SynchronizerTest, LateStartingCameraDropsTheOthersEarlyFrames) {
  Synchronizer sync(2, milliseconds(10));
  const auto sets = run(sync, {{0, 33, 67, 100}, {66, 99}});
  ASSERT_EQ(sets.size(), 2u);
  EXPECT_EQ(sets[0], (std::vector<double>{67, 66}));
  EXPECT_EQ(sync.stats().unmatchedDropped[0], 2u);
}

TEST_F(SynchronizerTest, EndedCameraLeavesAnEmptySlot) {
  Synchronizer sync(2, milliseconds(10));
  const auto sets = run(sync, {{0, 33, 67}, {0}});
  ASSERT_EQ(sets.size(), 3u);
  EXPECT_EQ(sets[0], (std::vector<double>{0, 0}));
  EXPECT_EQ(sets[2], (std::vector<double>{67, -1}));
}

TEST_F(SynchronizerTest, BackwardsTimestampIsDroppedAndCounted) {
  Synchronizer sync(2, milliseconds(10));
  const auto sets = run(sync, {{0, 33, 20, 67}, {0, 33, 67}});
  ASSERT_EQ(sets.size(), 3u);
  EXPECT_EQ(sets[2], (std::vector<double>{67, 67}));
  EXPECT_EQ(sync.stats().outOfOrderDropped[0], 1u);
}

TEST_F(SynchronizerTest, FramesGoBackToThePoolWhenDropped) {
  Synchronizer sync(2, milliseconds(10));
  run(sync, {{0, 33, 67, 100, 133}, {1, 68, 134}});
  EXPECT_EQ(pool_.available(), pool_.capacity());
}

// Live: a camera that has not delivered does not hold the others back past the deadline; the set
// goes without it, counted, and the skew of what was sent is kept.
TEST_F(SynchronizerTest, ALateCameraIsLeftOutAfterTheDeadline) {
  Synchronizer sync(3, milliseconds(10));
  sync.offer(0, frameAt(100));
  sync.offer(1, frameAt(104));
  EXPECT_FALSE(sync.pop().has_value());  // camera 2 has not delivered
  EXPECT_FALSE(sync.popLate(milliseconds(140), milliseconds(50)).has_value());  // still in time
  const auto set = sync.popLate(milliseconds(151), milliseconds(50));
  ASSERT_TRUE(set.has_value());
  EXPECT_NE(set->frame(0), nullptr);
  EXPECT_NE(set->frame(1), nullptr);
  EXPECT_EQ(set->frame(2), nullptr);
  EXPECT_EQ(sync.stats().lateMissing[2], 1u);
  EXPECT_EQ(sync.stats().lateMissing[0], 0u);
  EXPECT_EQ(sync.stats().maxSpread, milliseconds(4));
  EXPECT_EQ(sync.stats().meanSpread(), milliseconds(4));
  // The late camera's next frame meets the others' next ones as usual.
  sync.offer(0, frameAt(133));
  sync.offer(1, frameAt(137));
  sync.offer(2, frameAt(135));
  const auto next = sync.pop();
  ASSERT_TRUE(next.has_value());
  EXPECT_NE(next->frame(2), nullptr);
  EXPECT_EQ(sync.stats().meanSpread(), milliseconds(4));  // (4 + 4) / 2
}

TEST_F(SynchronizerTest, NothingIsSentLateWhenNoCameraHasDelivered) {
  Synchronizer sync(2, milliseconds(10));
  EXPECT_FALSE(sync.popLate(milliseconds(1000), milliseconds(50)).has_value());
}

TEST_F(SynchronizerTest, RejectsImpossibleCameraCounts) {
  EXPECT_THROW(Synchronizer(0, milliseconds(10)), std::invalid_argument);
  EXPECT_THROW(Synchronizer(kMaxCameras + 1, milliseconds(10)), std::invalid_argument);
}

}  // namespace
}  // namespace surroundd::capture
