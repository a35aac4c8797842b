// With identity photometrics the videos are the noise-free ground-truth camera images, up to the
// codec's error: what a geometry test can rely on when it decodes a recording.

#include <gtest/gtest.h>

#include "tests/synth/synth_test_support.hpp"

namespace surroundd::synth {
namespace {

TEST(SynthIdentity, VideoFramesAreTheNoiseFreeImages) {
  const auto folder = testing::fixture("synth_small_identity");
  const YAML::Node truth = YAML::LoadFile((folder / "ground_truth.yaml").string());
  for (const auto& camera : truth["cameras"]) {
    const auto p = camera["photometrics"];
    EXPECT_EQ(p["gain"].as<double>(), 1.0);
    EXPECT_EQ(p["gamma"].as<double>(), 1.0);
    EXPECT_EQ(p["noise_sigma"].as<double>(), 0.0);
    EXPECT_EQ(p["drift_amplitude"].as<double>(), 0.0);
    EXPECT_EQ(p["vignetting"].as<double>(), 0.0);
    const auto frames = testing::decodeAll(folder / camera["video"].as<std::string>()).images;
    ASSERT_EQ(static_cast<int>(frames.size()), truth["frames"].as<int>());
    for (const auto& entry : truth["ground_truth_frames"]) {
      const int k = entry["frame"].as<int>();
      const auto name = camera["name"].as<std::string>();
      const cv::Mat expected =
          cv::imread((folder / entry["cameras"][name]["image"].as<std::string>()).string());
      ASSERT_EQ(expected.size(), frames[static_cast<std::size_t>(k)].size());
      const double psnr = cv::PSNR(expected, frames[static_cast<std::size_t>(k)]);
      EXPECT_GE(psnr, 38.0) << name << " frame " << k;
      // The ratio of video to truth is 1 on average: no gain sneaks in through the codec path.
      const cv::Scalar ratio = cv::mean(frames[static_cast<std::size_t>(k)]) / 1.0;
      const cv::Scalar reference = cv::mean(expected);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(ratio[c] / reference[c], 1.0, 0.01) << name;
    }
  }
}

}  // namespace
}  // namespace surroundd::synth
