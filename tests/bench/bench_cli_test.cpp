// surround-bench stitch on a small recording: it measures what it says (timings against the
// cv::remap baseline, accuracy for both projections) and prints it as JSON for machines; bad
// command lines are usage errors.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "tests/support/child_process.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd {
namespace {

using ::testing::HasSubstr;

const std::string kRecording = std::string(SURROUNDD_FIXTURE_DIR) + "/synth_small";

TEST(BenchCli, StitchReportsTimingsAndAccuracyAsJson) {
  const testing::TempDir dir;
  testing::ChildProcess bench({SURROUND_BENCH, "stitch", "--json", "--repeats", "3", kRecording},
                              dir / "out.txt");
  ASSERT_EQ(bench.wait(), 0) << bench.output();
  const YAML::Node report = YAML::Load(bench.output())["stitch"][0];
  EXPECT_EQ(report["input"].as<std::string>(), "synth_small");
  EXPECT_EQ(report["panorama"][0].as<int>(), 512);
  EXPECT_GT(report["lut_build_s"].as<double>(), 0);
  ASSERT_EQ(report["timings"].size(), 2u);  // 1 thread and the default 2
  for (const auto& timing : report["timings"]) {
    EXPECT_GT(timing["stitch_ms"].as<double>(), 0);
    EXPECT_GT(timing["remap_ms"].as<double>(), 0);
    EXPECT_NEAR(timing["ratio"].as<double>(),
                timing["stitch_ms"].as<double>() / timing["remap_ms"].as<double>(), 1e-3);
  }
  EXPECT_LT(report["bowl"]["seam_mean_px"].as<double>(), 0.01);
  EXPECT_GT(report["sphere"]["seam_mean_px"].as<double>(), 3.0);
  EXPECT_LT(report["bowl"]["ground_mae_levels"].as<double>(),
            report["sphere"]["ground_mae_levels"].as<double>());
}

TEST(BenchCli, BadCommandLinesAreUsageErrors) {
  const testing::TempDir dir;
  for (const auto& [arguments, message] :
       {std::pair{std::vector<std::string>{"stitch"}, "no recording given"},
        std::pair{std::vector<std::string>{"stich", kRecording}, "expected 'stitch' or 'colour'"},
        std::pair{std::vector<std::string>{"stitch", "--threads", "0", kRecording},
                  "--threads needs a number from 1 to 256"},
        std::pair{std::vector<std::string>{"stitch", "--fast", kRecording},
                  "unknown option '--fast'"}}) {
    std::vector<std::string> argv{SURROUND_BENCH};
    argv.insert(argv.end(), arguments.begin(), arguments.end());
    testing::ChildProcess bench(argv, dir / "out.txt");
    EXPECT_EQ(bench.wait(), 2) << message;
    EXPECT_THAT(bench.output(), HasSubstr(message));
  }
  testing::ChildProcess missing({SURROUND_BENCH, "stitch", (dir / "nothing").string()},
                                dir / "out.txt");
  EXPECT_EQ(missing.wait(), 1);
  EXPECT_THAT(missing.output(), HasSubstr("rig.yaml"));
}

}  // namespace
}  // namespace surroundd
