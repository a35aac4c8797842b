// Issue 18: an exception from a stage on the pipeline thread reached main's catch-all and ended
// the service, losing the recording's end. Now a frame set a stage fails on is dropped and
// counted, the run goes on and finalizes its outputs; many failures in a row end the run asking
// for a rebuild. The failures come through the observer's per-set hook, which counts as a stage.
// And a camera that sees only its own car (issue 47: a real camera inside the body's box) is
// named with the body as the cause, and the daemon runs with the others.

#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "daemon/pipeline.hpp"
#include "tests/daemon/replay_config.hpp"
#include "tests/support/log_capture.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {
namespace {

// Throws on the sets whose number (from 0) `fails` says.
class FailingStage final : public PipelineObserver {
 public:
  explicit FailingStage(std::function<bool(int)> fails) : fails_(std::move(fails)) {}
  void onLoop(Pipeline& /*pipeline*/, std::chrono::steady_clock::time_point /*now*/,
              std::uint64_t /*frameSets*/) override {}
  void onStopping() override {}
  void onFrameSet(Pipeline& /*pipeline*/, const capture::FrameSet& /*set*/) override {
    if (fails_(sets_++)) throw std::runtime_error("a stage failed on this set");
  }

 private:
  std::function<bool(int)> fails_;
  int sets_ = 0;
};

Config mosaicReplay(const std::filesystem::path& out) {
  return fixtureReplay("synth_small", {videoOutputAt(out / "mosaic.mkv")});
}

TEST(FaultIsolation, AFailedSetIsDroppedAndTheRunGoesOn) {
  const testing::TempDir dir;
  Pipeline pipeline(mosaicReplay(dir.path()));
  FailingStage stage([](int set) { return set >= 3 && set < 6; });
  const std::atomic<bool> stop{false};
  const RunSummary summary = pipeline.run(stop, &stage);
  EXPECT_EQ(summary.failedSets, 3u);
  EXPECT_FALSE(summary.rebuild);
  EXPECT_EQ(summary.failedOutputs, 0u);
  const auto video = surroundd::testing::decodeAll(dir / "mosaic.mkv");
  EXPECT_EQ(video.last, capture::ReadStatus::kEndOfStream);  // finalized
  EXPECT_EQ(video.images.size(), summary.frameSets);
  EXPECT_GT(summary.frameSets, 10u);
  EXPECT_EQ(pipeline.report().failedSets, 3u);
}

TEST(FaultIsolation, FailuresInARowEndTheRunForARebuild) {
  const testing::TempDir dir;
  Pipeline pipeline(mosaicReplay(dir.path()));
  FailingStage stage([](int set) { return set >= 2; });
  const std::atomic<bool> stop{false};
  const RunSummary summary = pipeline.run(stop, &stage);
  EXPECT_TRUE(summary.rebuild);
  EXPECT_EQ(summary.frameSets, 2u);
  EXPECT_EQ(summary.failedSets, static_cast<std::uint64_t>(Pipeline::kRebuildAfterFailures));
  // What it wrote before is finalized, not lost.
  EXPECT_EQ(surroundd::testing::decodeAll(dir / "mosaic.mkv").images.size(), 2u);
}

TEST(FaultIsolation, ACameraThatSeesOnlyTheBodyIsNamedAndTheOthersRun) {
  const testing::TempDir dir;
  OutputConfig video = videoOutputAt(dir / "panorama.mp4");
  video.stream = OutputStream::kPanorama;
  Config config = fixtureReplay("synth_small", {video});
  useSmallPanorama(config, dir / "lut");
  const cv::Size size = config.cameras[2].calibration.intrinsics.imageSize;
  const double right = size.width - 1, bottom = size.height - 1;
  BodyMaskConfig everything;  // the whole picture is body
  everything.mode = BodyMaskConfig::Mode::kReplace;
  everything.polygons = {{{0.0, 0.0}, {right, 0.0}, {right, bottom}, {0.0, bottom}}};
  config.cameras[2].bodyMask = everything;
  std::vector<std::string> log;
  RunSummary summary;
  {
    const testing::LogCapture capture;
    Pipeline pipeline(config);
    const std::atomic<bool> stop{false};
    summary = pipeline.run(stop);
    log = capture.lines();
  }
  EXPECT_THAT(log, ::testing::Contains(::testing::HasSubstr(
                       "camera 'back' contributes nothing to the panorama: its body mask (100 % "
                       "of its picture) hides all it would show; the panorama is made from the "
                       "other cameras")));
  EXPECT_EQ(summary.frameSets, 30U);
  EXPECT_EQ(testing::decodeAll(dir / "panorama.mp4").images.size(), 30U);
}

}  // namespace
}  // namespace surroundd::daemon
