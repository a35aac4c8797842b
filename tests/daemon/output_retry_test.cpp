// Issue 18: an output that failed was dropped for good, and a recorder with every output failed
// looked healthy. Now a failed output is opened again after a pause (doubling up to a minute) under
// a name that keeps what it wrote, and the pipeline says when no output works. The failure here
// is real: while the first segment is written, a folder takes the second segment's file name, so
// that segment cannot be opened.

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "daemon/pipeline.hpp"
#include "tests/daemon/replay_config.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {
namespace {

// Takes the second segment's name once the first is being written, and watches whether some
// output works, loop by loop.
class OutputWatch final : public PipelineObserver {
 public:
  explicit OutputWatch(std::filesystem::path obstacle) : obstacle_(std::move(obstacle)) {}
  void onLoop(Pipeline& pipeline, std::chrono::steady_clock::time_point /*now*/,
              std::uint64_t frameSets) override {
    if (frameSets >= 2) std::filesystem::create_directories(obstacle_);
    (pipeline.outputsWork() ? sawWorking : sawNone) = true;
    if (sawNone && pipeline.outputsWork() && !sawBack) {
      sawBack = true;
      setsBeforeBack = frameSets;
    }
  }
  void onStopping() override {}
  bool sawWorking = false, sawNone = false, sawBack = false;
  std::uint64_t setsBeforeBack = 0;  // the sets the pipeline had made when the output came back

 private:
  std::filesystem::path obstacle_;
};

TEST(OutputRetry, AFailedOutputIsOpenedAgainAndNothingItWroteIsLost) {
  const testing::TempDir dir;
  // Two seconds of frames, played in real time, so that the retry after 1 s comes within the run.
  OutputConfig video = videoOutputAt(dir / "drive.mkv");
  video.segmentS = 0.25;
  Config config = fixtureReplay("synth_drop", {video});
  config.capture.pacing = capture::Pacing::kRealtime;
  Pipeline pipeline(config);
  OutputWatch watch(dir / "drive-00002.mkv.part" / "taken");
  const std::atomic<bool> stop{false};
  const RunSummary summary = pipeline.run(stop, &watch);
  EXPECT_EQ(summary.failedOutputs, 1u);
  EXPECT_TRUE(watch.sawNone);
  EXPECT_TRUE(watch.sawBack);
  // The first segment is whole; after the retry, segments go on after the highest number there.
  EXPECT_GT(surroundd::testing::decodeAll(dir / "drive-00001.mkv").images.size(), 3u);
  EXPECT_TRUE(std::filesystem::is_directory(dir / "drive-00002.mkv.part" / "taken"));
  std::size_t after = 0;
  for (int segment = 3; std::filesystem::exists(dir / fmt::format("drive-{:05}.mkv", segment));
       ++segment) {
    const auto part = surroundd::testing::decodeAll(dir / fmt::format("drive-{:05}.mkv", segment));
    EXPECT_EQ(part.last, capture::ReadStatus::kEndOfStream) << segment;
    after += part.images.size();
  }
  // Every set made once it was back is in them (not a share of the run's time: under TSan the
  // run's start was slow enough to leave only 9 sets after the retry).
  EXPECT_GT(after, 0u);
  EXPECT_GE(after, summary.frameSets - watch.setsBeforeBack);
}

}  // namespace
}  // namespace surroundd::daemon
