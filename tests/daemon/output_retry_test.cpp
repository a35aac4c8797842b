// Issue 18: an output that failed was dropped for good, and a recorder with every output failed
// looked healthy. Now a failed output is opened again after a pause (doubling up to a minute) under
// a name that keeps what it wrote, and the pipeline says when no output works. The failure here
// is real: while the first segment is written, a folder takes the second segment's file name, so
// that segment cannot be opened.

#include <atomic>
#include <optional>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "daemon/pipeline.hpp"
#include "tests/daemon/replay_config.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {
namespace {

// Takes the second segment's name once the first is being written, watches whether some output
// works, loop by loop, and stops the run once kSetsAfterReturn frame sets went through after the
// output came back.
class OutputWatch final : public PipelineObserver {
 public:
  static constexpr std::uint64_t kSetsAfterReturn = 10;

  OutputWatch(std::filesystem::path obstacle, std::atomic<bool>& stop)
      : obstacle_(std::move(obstacle)), stop_(stop) {}
  void onLoop(Pipeline& pipeline, std::chrono::steady_clock::time_point /*now*/,
              std::uint64_t frameSets) override {
    if (frameSets >= 2) std::filesystem::create_directories(obstacle_);
    const bool works = pipeline.outputsWork();
    (works ? sawWorking : sawNone) = true;
    if (sawNone && works && !back) back = frameSets;
    if (back && frameSets >= *back + kSetsAfterReturn) stop_ = true;
  }
  void onStopping() override {}
  bool sawWorking = false, sawNone = false;
  std::optional<std::uint64_t> back;  // the frame sets gone through when the output worked again

 private:
  std::filesystem::path obstacle_;
  std::atomic<bool>& stop_;
};

TEST(OutputRetry, AFailedOutputIsOpenedAgainAndNothingItWroteIsLost) {
  const testing::TempDir dir;
  // The recording looping in real time, so that the retry after 1 s comes within the run however
  // slow the machine (an emulator too: scripts/cross-arm64.sh); stopped by the watch.
  OutputConfig video = videoOutputAt(dir / "drive.mkv");
  video.segmentS = 0.25;
  Config config = fixtureReplay("synth_drop", {video});
  config.capture.pacing = capture::Pacing::kRealtime;
  for (auto& camera : config.cameras) camera.source->loop = true;
  Pipeline pipeline(config);
  std::atomic<bool> stop{false};
  OutputWatch watch(dir / "drive-00002.mkv.part" / "taken", stop);
  const RunSummary summary = pipeline.run(stop, &watch);
  EXPECT_EQ(summary.failedOutputs, 1u);
  EXPECT_TRUE(watch.sawNone);
  ASSERT_TRUE(watch.back);
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
  // Every frame set made once it was back is in them.
  EXPECT_GE(after, summary.frameSets - *watch.back);
  EXPECT_GE(after, OutputWatch::kSetsAfterReturn);
}

}  // namespace
}  // namespace surroundd::daemon
