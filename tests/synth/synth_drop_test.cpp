// --drop-every: the dropping camera's video and timestamps have the gaps its rule says, the others
// none; every camera starts within its 0..4 ms offset and keeps to +-1 ms of jitter.

#include <gtest/gtest.h>

#include "tests/synth/synth_test_support.hpp"

namespace surroundd::synth {
namespace {

TEST(SynthDrop, TimestampsFollowTheRules) {
  const auto folder = testing::fixture("synth_drop");
  const YAML::Node truth = YAML::LoadFile((folder / "ground_truth.yaml").string());
  const int frames = truth["frames"].as<int>();
  const double periodUs = 1e6 / truth["fps"].as<double>();
  int dropping = 0;
  for (const auto& camera : truth["cameras"]) {
    const int dropEvery = camera["drop_every"].as<int>();
    const auto timestamps = camera["timestamps_us"].as<std::vector<std::int64_t>>();
    const int expected = dropEvery > 0 ? frames - frames / dropEvery : frames;
    EXPECT_EQ(camera["frames_written"].as<int>(), expected);
    ASSERT_EQ(static_cast<int>(timestamps.size()), expected);
    const double offsetMs = camera["start_offset_ms"].as<double>();
    EXPECT_GE(offsetMs, 0.0);
    EXPECT_LE(offsetMs, 4.0);
    int gaps = 0;
    for (std::size_t i = 1; i < timestamps.size(); ++i) {
      const double steps = static_cast<double>(timestamps[i] - timestamps[i - 1]) / periodUs;
      const bool one = std::abs(steps - 1) * periodUs <= 2000;
      const bool two = std::abs(steps - 2) * periodUs <= 2000;
      EXPECT_TRUE(one || two) << camera["name"] << " " << i;
      gaps += two ? 1 : 0;
    }
    EXPECT_EQ(gaps, dropEvery > 0 ? frames / dropEvery - (frames % dropEvery == 0 ? 1 : 0) : 0);
    if (dropEvery > 0) {
      ++dropping;
      const auto video = testing::decodeAll(folder / camera["video"].as<std::string>()).images;
      EXPECT_EQ(static_cast<int>(video.size()), expected);
    }
  }
  EXPECT_EQ(dropping, 1);
}

}  // namespace
}  // namespace surroundd::synth
