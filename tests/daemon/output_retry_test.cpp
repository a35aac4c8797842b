// Issue 18: an output that failed was dropped for good, and a recorder with every output failed
// looked healthy. Now a failed output is opened again after a pause (doubling up to a minute) under
// a name that keeps what it wrote, and the pipeline says when no output works. The failure in the
// pipeline's test is real: while the first segment is written, a folder takes the second segment's
// file name, so that segment cannot be opened. The pauses are tested on the outputs alone, with
// an output type of this test's own that fails when told to.

#include <atomic>
#include <optional>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "daemon/config/output_type.hpp"
#include "daemon/pipeline.hpp"
#include "daemon/pipeline_outputs.hpp"
#include "tests/daemon/replay_config.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {
namespace {

// An output that fails when told to: its pictures while `consumeFails`, its opening while
// `openFails`; `opens` counts the tries to open it.
struct FlakyState {
  bool consumeFails = false;
  bool openFails = false;
  int opens = 0;
};
FlakyState& flaky() {
  static FlakyState state;
  return state;
}

class FlakySink final : public render::FrameSink {
 public:
  void consume(const cv::Mat& /*bgr*/, const render::PictureTime& /*time*/) override {
    if (flaky().consumeFails) throw std::runtime_error("flaky: the picture was refused");
  }
  void finish(const cv::Mat& /*lastFrame*/, std::chrono::nanoseconds /*lastTime*/) override {}
  std::string describe() const override { return "flaky"; }
};

bool flakyRegistered() {
  static const bool kDone = [] {
    OutputType type;
    type.name = "flaky";
    type.readSettings = [](YamlObject&, const OutputConfig&) { return OutputSettings(); };
    type.openPictureSink = [](const OutputConfig&, const OutputContext&) {
      ++flaky().opens;
      if (flaky().openFails) throw std::runtime_error("flaky: cannot open");
      return std::unique_ptr<render::FrameSink>(std::make_unique<FlakySink>());
    };
    registerOutputType(std::move(type));
    return true;
  }();
  return kDone;
}

TEST(OutputRetry, AnOutputStillFailingIsTriedAfterTwiceThePauseEachTimeUpToAMinute) {
  ASSERT_TRUE(flakyRegistered());
  using Clock = PipelineOutputs::Clock;
  OutputConfig config;
  config.kind = OutputKind{"flaky"};
  PipelineOutputs outputs(30, false);
  outputs.addPicture(config, cv::Size(64, 48), nullptr, nullptr);
  auto& output = outputs.pictures().at(0);
  const cv::Mat picture(48, 64, CV_8UC3, cv::Scalar::all(90));

  flaky() = {true, true, 0};
  const auto failedAt = Clock::now();
  outputs.handOver(output, picture, {}, failedAt);
  ASSERT_FALSE(output.sink);
  EXPECT_FALSE(outputs.anyWorks());
  EXPECT_EQ(outputs.failures(), 1u);

  // Each pause from a failed try to the next: 1 s after the failure, then 2, 4, ... up to 60 s.
  auto now = output.nextRetry;
  EXPECT_GE(now - failedAt, std::chrono::seconds(1));
  for (const int pause : {2, 4, 8, 16, 32, 60, 60}) {
    SCOPED_TRACE(pause);
    outputs.retry(now - std::chrono::milliseconds(1));  // not yet
    EXPECT_EQ(flaky().opens, 0);
    outputs.retry(now);
    EXPECT_EQ(flaky().opens, 1);
    EXPECT_EQ(output.nextRetry - now, std::chrono::seconds(pause));
    flaky().opens = 0;
    now = output.nextRetry;
  }

  // Once it opens it is on trial (issue 51: an output opened on a full disk fails at its first
  // writes): it counts as failed, and failing then keeps the pause as long as it was.
  flaky() = {false, false, 0};
  outputs.retry(now);
  ASSERT_TRUE(output.sink);
  EXPECT_FALSE(outputs.anyWorks());
  flaky().consumeFails = true;
  outputs.handOver(output, picture, {}, Clock::now());
  ASSERT_FALSE(output.sink);
  EXPECT_EQ(output.retryDelay, PipelineOutputs::kLastOutputRetry);

  // Opened kOutputTrial ago and taking pictures: it works again, and a later failure starts the
  // pauses again from 1 s.
  flaky() = {false, false, 0};
  output.nextRetry = {};
  outputs.retry(Clock::now() - PipelineOutputs::kOutputTrial);
  ASSERT_TRUE(output.sink);
  EXPECT_FALSE(outputs.anyWorks());
  outputs.handOver(output, picture, {}, Clock::now());
  EXPECT_TRUE(outputs.anyWorks());
  flaky().consumeFails = true;
  outputs.handOver(output, picture, {}, Clock::now());
  ASSERT_FALSE(output.sink);
  EXPECT_EQ(output.retryDelay, PipelineOutputs::kFirstOutputRetry);
  EXPECT_EQ(outputs.failures(), 3u);
}

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
  VideoOutputSettings segmented;
  segmented.segmentS = 0.25;
  OutputConfig video = videoOutputAt(dir / "drive.mkv", segmented);
  Config config = fixtureReplay("synth_drop", {video});
  config.capture.pacing = capture::Pacing::kRealtime;
  for (auto& camera : config.cameras) camera.replayedFile()->loop = true;
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
