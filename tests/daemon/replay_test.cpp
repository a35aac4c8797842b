// Replay of a generated recording in which one camera drops frames: the file sources deliver the
// recorded timestamps, and the pipeline loses exactly the frame sets that camera misses.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "capture/file_source.hpp"
#include "daemon/config/rig_yaml.hpp"
#include "daemon/pipeline.hpp"
#include "tests/daemon/replay_config.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd::daemon {
namespace {

// A function: a static path's construction could throw before main (cert-err58-cpp).
std::filesystem::path recording() {
  return std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_drop";
}

std::vector<capture::Timestamp> timestampsOf(const std::filesystem::path& file) {
  capture::FileSource source("check", {file, 30.0, false, capture::Pacing::kAsFastAsPossible});
  capture::Frame frame;
  frame.image.create(source.frameSize(), CV_8UC3);
  std::vector<capture::Timestamp> timestamps;
  while (source.read(frame) == capture::ReadStatus::kFrame) timestamps.push_back(frame.timestamp);
  return timestamps;
}

class ReplayTest : public ::testing::Test {
 protected:
  void SetUp() override {
    config_.cameras = loadRigFile(recording() / "rig.yaml");
    for (const auto& camera : config_.cameras)
      timestamps_.push_back(timestampsOf(camera.replayedFile()->path));
    const auto fewest =
        std::min_element(timestamps_.begin(), timestamps_.end(),
                         [](const auto& a, const auto& b) { return a.size() < b.size(); });
    dropping_ = static_cast<std::size_t>(fewest - timestamps_.begin());
  }

  // Replayed as fast as possible, with one output: `stream`'s last picture (320x180) into `file`.
  void replayIntoLastPicture(const std::filesystem::path& file, OutputStream stream) {
    config_.capture.pacing = capture::Pacing::kAsFastAsPossible;
    config_.render.widthPx = 320;
    config_.render.heightPx = 180;
    config_.outputs = {snapshotAt(file, stream, 1e6)};
  }

  Config config_;
  std::vector<std::vector<capture::Timestamp>> timestamps_;
  std::size_t dropping_ = 0;
};

TEST_F(ReplayTest, TimestampsAreTheRecordedOnes) {
  using std::chrono::milliseconds;
  const auto period = std::chrono::nanoseconds(33'333'333);
  for (std::size_t c = 0; c < timestamps_.size(); ++c) {
    const auto& t = timestamps_[c];
    ASSERT_GT(t.size(), 10u);
    // Cameras start within a few milliseconds of each other, as a real rig does.
    EXPECT_LT(std::chrono::abs(t.front() - timestamps_[0].front()), milliseconds(8)) << c;
    int gaps = 0;
    for (std::size_t i = 1; i < t.size(); ++i) {
      const auto step = t[i] - t[i - 1];
      const bool onePeriod = std::chrono::abs(step - period) <= milliseconds(3);
      const bool twoPeriods = std::chrono::abs(step - 2 * period) <= milliseconds(3);
      EXPECT_TRUE(onePeriod || twoPeriods) << "camera " << c << " frame " << i;
      gaps += twoPeriods ? 1 : 0;
    }
    // Only the dropping camera has gaps, one per frame it left out (its last frame may be one).
    const auto& other = timestamps_[(dropping_ + 1) % timestamps_.size()];
    const auto missing = static_cast<int>(other.size() - t.size());
    const int atTheEnd = static_cast<int>(std::lround((other.back() - t.back()) / period));
    EXPECT_EQ(gaps + atTheEnd, missing) << "camera " << c;
    if (c == dropping_) {
      EXPECT_GT(gaps, 0);
    }
  }
  EXPECT_GT(timestamps_[(dropping_ + 1) % timestamps_.size()].size(),
            timestamps_[dropping_].size());
}

TEST_F(ReplayTest, PipelineLosesOnlyTheSetsOfTheDroppedFrames) {
  const testing::TempDir dir;
  replayIntoLastPicture(dir / "last.png", OutputStream::kMosaic);

  Pipeline pipeline(config_);
  const std::atomic<bool> stop{false};
  const RunSummary summary = pipeline.run(stop);

  // Each frame the camera left out while it ran costs one set; after its last frame the others go
  // on with its slot empty.
  const auto& dropping = timestamps_[dropping_];
  std::size_t leftOut = 0;
  for (std::size_t i = 1; i < dropping.size(); ++i) {
    leftOut += dropping[i] - dropping[i - 1] > std::chrono::milliseconds(50) ? 1 : 0;
  }
  const std::size_t others = timestamps_[(dropping_ + 1) % timestamps_.size()].size();
  EXPECT_EQ(summary.frameSets, others - leftOut);
  for (std::size_t c = 0; c < timestamps_.size(); ++c) {
    EXPECT_EQ(summary.cameras[c].frames, timestamps_[c].size()) << c;
    EXPECT_EQ(summary.sync.unmatchedDropped[c], c == dropping_ ? 0 : leftOut) << c;
    EXPECT_EQ(summary.sync.outOfOrderDropped[c], 0u);
  }
  EXPECT_LE(summary.sync.maxSpread, std::chrono::milliseconds(10));
  EXPECT_TRUE(std::filesystem::exists(dir / "last.png"));
}

// Holds the pipeline thread once, after its first frame set, until every camera has newer frames
// queued: what a slow stitch does live, made certain rather than left to the machine's speed (under
// CI load or a sanitizer, decoding need not outrun processing). Bounded: 30 s.
class HoldUntilQueued final : public PipelineObserver {
 public:
  void onLoop(Pipeline& pipeline, std::chrono::steady_clock::time_point /*now*/,
              std::uint64_t frameSets) override {
    if (held_ || frameSets == 0) return;
    held_ = true;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (!everyCameraQueued(pipeline)) {
      if (std::chrono::steady_clock::now() > deadline) {
        ADD_FAILURE() << "the cameras never queued frames while the pipeline was held";
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  void onStopping() override {}

 private:
  static bool everyCameraQueued(const Pipeline& pipeline) {
    const auto report = pipeline.report();
    return std::ranges::all_of(report.cameras,
                               [](const CameraReport& camera) { return camera.queued >= 2; });
  }
  bool held_ = false;
};

// Seen as live: while the pipeline works on a set, newer ones come (here: while it is held), so
// sets go stale; they are skipped and counted, and no set is lost without being counted.
TEST_F(ReplayTest, LatestWinsSkipsStaleSetsAndCountsThem) {
  const testing::TempDir dir;
  config_.capture.pacing = capture::Pacing::kAsFastAsPossible;
  config_.outputs = {snapshotAt(dir / "last.png", OutputStream::kPanorama, 1e6)};
  const auto replay = [&](CaptureConfig::LatestWins latestWins) {
    config_.capture.latestWins = latestWins;
    Pipeline pipeline(config_);
    const std::atomic<bool> stop{false};
    HoldUntilQueued hold;
    return pipeline.run(stop, &hold);
  };
  const RunSummary every = replay(CaptureConfig::LatestWins::kAuto);  // files: every set
  EXPECT_EQ(every.report.staleDropped, 0u);
  const RunSummary newest = replay(CaptureConfig::LatestWins::kAlways);
  EXPECT_GT(newest.report.staleDropped, 0u);
  EXPECT_LT(newest.frameSets, every.frameSets);
  EXPECT_EQ(newest.frameSets + newest.report.staleDropped, every.frameSets);
  for (std::size_t c = 0; c < timestamps_.size(); ++c) {
    EXPECT_EQ(newest.cameras[c].frames, timestamps_[c].size()) << c;  // every frame was read
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "last.png"));
}

TEST_F(ReplayTest, AVideoOfAnotherSizeThanItsCalibrationIsRefused) {
  config_.cameras[1].calibration.intrinsics.imageSize = {640, 360};
  try {
    Pipeline pipeline(config_);
    FAIL() << "a 320x180 video with a 640x360 calibration was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("has 320x180 frames but the lens is calibrated for "
                                               "640x360"));
  }
}

// The cameras open all at once (each file's decoder set up on a thread of its own): when several
// cannot, the one named is the first in the rig, every time, as when they opened in turn.
TEST_F(ReplayTest, OfCamerasThatCannotOpenTheFirstInTheRigIsNamed) {
  config_.cameras[1].replayedFile()->path = "/nonexistent/right.mkv";
  config_.cameras[3].replayedFile()->path = "/nonexistent/left.mkv";
  for (int attempt = 0; attempt < 5; ++attempt) {
    try {
      Pipeline pipeline(config_);
      FAIL() << "a rig with two missing videos was opened";
    } catch (const std::exception& e) {
      EXPECT_THAT(e.what(), ::testing::HasSubstr("/nonexistent/right.mkv"));
      EXPECT_THAT(e.what(), ::testing::Not(::testing::HasSubstr("left.mkv")));
    }
  }
}

// The renderer opens on a thread of its own while the cameras open. When a camera cannot, the
// error is the camera's, and the renderer opened meanwhile goes with the failed start (its scene's
// GL objects deleted in its own context); a pipeline made next on the same thread draws its view.
TEST_F(ReplayTest, ARendererOpenedBesideACameraThatCannotOpenGoesWithIt) {
  const testing::TempDir dir;
  replayIntoLastPicture(dir / "last.png", OutputStream::kSurround);
  Config broken = config_;
  broken.cameras[2].replayedFile()->path = "/nonexistent/back.mkv";
  try {
    const Pipeline pipeline(broken);
    FAIL() << "a rig with a missing video was opened";
  } catch (const std::exception& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("/nonexistent/back.mkv"));
  }

  Pipeline pipeline(config_);
  const std::atomic<bool> stop{false};
  EXPECT_GT(pipeline.run(stop).frameSets, 10u);
  const cv::Mat last = cv::imread((dir / "last.png").string());
  ASSERT_EQ(last.size(), cv::Size(320, 180));
  EXPECT_GT(cv::mean(last)[1], 20.0);  // the ground, not an empty picture
}

}  // namespace
}  // namespace surroundd::daemon
