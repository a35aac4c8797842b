// The health monitor on hand-made frame sets: each fault it names, how soon, and recovery.

#include "capture/camera_health.hpp"

#include <gtest/gtest.h>

#include "tests/support/test_support.hpp"

namespace surroundd::capture {
namespace {

using std::chrono::milliseconds;

class CameraHealthMonitorTest : public ::testing::Test {
 protected:
  // A set at `ms` with camera 0's picture given (or none) and camera 1 always fine.
  const std::vector<HealthChange>& observe(int ms, const cv::Mat* picture) {
    FrameSet set;
    set.cameraCount = 2;
    set.timestamp = milliseconds(ms);
    if (picture != nullptr) {
      set.frames[0] = pool_.tryAcquire();
      picture->copyTo(set.frames[0]->image);
    }
    set.frames[1] = pool_.tryAcquire();
    surroundd::testing::syntheticPicture(kSize, ms).copyTo(set.frames[1]->image);
    return monitor_.observe(set, sync_);
  }
  cv::Mat moving(int k) const { return surroundd::testing::syntheticPicture(kSize, k); }

  inline static const cv::Size kSize{64, 48};
  FramePool pool_{8, kSize};
  SyncStats sync_;
  CameraHealthMonitor monitor_{2};
};

TEST_F(CameraHealthMonitorTest, AMovingPictureIsFine) {
  for (int k = 0; k < 10; ++k) {
    const cv::Mat picture = moving(k);
    EXPECT_TRUE(observe(k * 33, &picture).empty());
  }
  EXPECT_EQ(monitor_.health(0), CameraHealth::kOk);
}

TEST_F(CameraHealthMonitorTest, ARepeatedPictureIsFrozenOnItsThirdShowingAndRecovers) {
  const cv::Mat still = moving(0);
  EXPECT_TRUE(observe(0, &still).empty());
  EXPECT_TRUE(observe(33, &still).empty());
  const auto changes = observe(67, &still);
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_EQ(changes[0].to, CameraHealth::kFrozen);
  const cv::Mat next = moving(5);
  EXPECT_EQ(observe(100, &next).at(0).to, CameraHealth::kOk);
}

// A still picture, looped: the same pixels for ever are what it is meant to show.
TEST_F(CameraHealthMonitorTest, WithoutTheFrozenCheckARepeatedPictureStaysFine) {
  monitor_.setFrozenCheck(0, false);
  const cv::Mat still = moving(0);
  for (int k = 0; k < 30; ++k) EXPECT_TRUE(observe(k * 33, &still).empty()) << k;
  EXPECT_EQ(monitor_.health(0), CameraHealth::kOk);
  // The other checks still hold.
  const cv::Mat black(kSize, CV_8UC3, cv::Scalar::all(3));
  EXPECT_EQ(observe(1000, &black).at(0).to, CameraHealth::kBlack);
  EXPECT_EQ(observe(1033, nullptr).size(), 0u);
  EXPECT_EQ(observe(1200, nullptr).at(0).to, CameraHealth::kLost);
}

TEST_F(CameraHealthMonitorTest, BlackAndBlindedPicturesAreSeenAtOnce) {
  const cv::Mat black(kSize, CV_8UC3, cv::Scalar::all(3));
  EXPECT_EQ(observe(0, &black).at(0).to, CameraHealth::kBlack);
  const cv::Mat white(kSize, CV_8UC3, cv::Scalar::all(252));
  EXPECT_EQ(observe(33, &white).at(0).to, CameraHealth::kSaturated);
}

TEST_F(CameraHealthMonitorTest, ACameraWithoutFramesIsLostAfter100Ms) {
  const cv::Mat picture = moving(0);
  observe(0, &picture);
  EXPECT_TRUE(observe(33, nullptr).empty());
  EXPECT_TRUE(observe(100, nullptr).empty());
  EXPECT_EQ(observe(133, nullptr).at(0).to, CameraHealth::kLost);
  EXPECT_EQ(monitor_.health(1), CameraHealth::kOk);
}

TEST_F(CameraHealthMonitorTest, FramesThatKeepMissingTheirSetsAreOutOfSync) {
  const cv::Mat picture = moving(0);
  observe(0, &picture);
  for (int k = 1; k <= 3; ++k) {
    ++sync_.unmatchedDropped[0];  // its frame came, but matched no set
    const auto& changes = observe(k * 33, nullptr);
    if (k < 3) {
      EXPECT_TRUE(changes.empty()) << k;
    } else {
      EXPECT_EQ(changes.at(0).to, CameraHealth::kOutOfSync);
    }
  }
}

TEST_F(CameraHealthMonitorTest, TimestampsThatStopMovingAreAFreeze) {
  const cv::Mat picture = moving(0);
  observe(0, &picture);
  ++sync_.outOfOrderDropped[0];
  EXPECT_TRUE(observe(33, nullptr).empty());
  ++sync_.outOfOrderDropped[0];
  EXPECT_EQ(observe(67, nullptr).at(0).to, CameraHealth::kFrozen);
}

}  // namespace
}  // namespace surroundd::capture
