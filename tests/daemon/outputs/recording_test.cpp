// Recording mode: record a replay of a generated recording, then replay the recording. Every
// camera's frames come back bit for bit with their original timestamps, and the recording's rig
// file drives surroundd like the original.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "daemon/config/rig_yaml.hpp"
#include "daemon/pipeline.hpp"
#include "tests/daemon/replay_config.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {
namespace {

const std::filesystem::path kRecording =
    std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_small";

RunSummary replay(const std::filesystem::path& rig, const std::vector<OutputConfig>& outputs) {
  const Config config = rigReplay(rig, outputs);
  Pipeline pipeline(config);
  const std::atomic<bool> stop{false};
  return pipeline.run(stop);
}

TEST(Recording, ReplaysFrameForFrameWithTheOriginalTimestamps) {
  const testing::TempDir dir;
  OutputConfig recording;
  recording.kind = OutputKind::kRecording;
  recording.path = dir / "drive";
  const RunSummary recorded = replay(kRecording / "rig.yaml", {recording});
  EXPECT_EQ(recorded.failedOutputs, 0u);
  ASSERT_EQ(recorded.outputs.size(), 1u);
  EXPECT_THAT(recorded.outputs[0], ::testing::HasSubstr("lossless"));

  const auto original = loadRigFile(kRecording / "rig.yaml");
  const auto copy = loadRigFile(dir / "drive/rig.yaml");
  ASSERT_EQ(copy.size(), original.size());
  for (std::size_t c = 0; c < original.size(); ++c) {
    SCOPED_TRACE(original[c].calibration.name);
    EXPECT_EQ(copy[c].calibration.name, original[c].calibration.name);
    EXPECT_EQ(copy[c].calibration.intrinsics.fx, original[c].calibration.intrinsics.fx);
    EXPECT_EQ(cv::norm(copy[c].calibration.pose.position, original[c].calibration.pose.position),
              0.0);
    EXPECT_EQ(copy[c].replayedFile()->path,
              dir / "drive" / (original[c].calibration.name + ".mp4"));
    const auto before = surroundd::testing::decodeAll(original[c].replayedFile()->path);
    const auto after = surroundd::testing::decodeAll(copy[c].replayedFile()->path);
    ASSERT_EQ(after.images.size(), before.images.size());
    EXPECT_EQ(after.timestamps, before.timestamps);
    for (std::size_t k = 0; k < before.images.size(); ++k) {
      ASSERT_EQ(cv::norm(after.images[k], before.images[k], cv::NORM_INF), 0.0) << "frame " << k;
    }
  }

  // The recording replays like the original.
  OutputConfig mosaic;
  mosaic.path = dir / "mosaic.mp4";
  const RunSummary replayed = replay(dir / "drive/rig.yaml", {mosaic});
  EXPECT_EQ(replayed.frameSets, recorded.frameSets);
  EXPECT_EQ(replayed.sync.maxSpread, recorded.sync.maxSpread);
}

}  // namespace
}  // namespace surroundd::daemon
