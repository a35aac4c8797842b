// surround-bench gpu-kit packs a recording's panorama LUT and first frame set for a machine with
// a GPU, and surround-gpu-check measures the GPU path on it (here through llvmpipe, as
// scripts/gpu-check.sh runs it there): the GPU panorama within the bounds of the CPU's
// for each camera format, every figure printed; broken kits are named.

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "processing/stitch/panorama_lut_cache.hpp"
#include "tests/support/child_process.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd {
namespace {

using ::testing::HasSubstr;

// NOLINTNEXTLINE(cert-err58-cpp): a path made once, before the tests; nothing to catch it.
const std::string kRecording = std::string(SURROUNDD_FIXTURE_DIR) + "/synth_small";

TEST(GpuCheckCli, MeasuresTheGpuPathOnTheKitGpuKitWrote) {
  const testing::TempDir dir;
  testing::ChildProcess kit({SURROUND_BENCH, "gpu-kit", (dir / "kits").string(), kRecording},
                            dir / "kit.txt");
  ASSERT_EQ(kit.wait(), 0) << kit.output();
  const auto folder = dir / "kits" / "synth_small";
  const auto lookup = processing::PanoramaLutCache::loadFile(folder / "panorama.lut");
  ASSERT_TRUE(lookup.lut) << lookup.problem;
  ASSERT_EQ(lookup.lut->cameraSizes.size(), 4u);
  for (std::size_t camera = 0; camera < 4; ++camera) {
    EXPECT_EQ(std::filesystem::file_size(folder / ("camera" + std::to_string(camera) + ".yuyv")),
              static_cast<std::uintmax_t>(lookup.lut->cameraSizes[camera].area()) * 2);
  }

  testing::ChildProcess check(
      {SURROUND_GPU_CHECK, "--frames", "2", "--view", "top", "--size", "320x180", folder.string()},
      dir / "check.txt");
  ASSERT_EQ(check.wait(), 0) << check.output();
  const std::string output = check.output();
  EXPECT_THAT(output, HasSubstr("surround-gpu-check: EGL "));
  EXPECT_THAT(output, HasSubstr("synth_small: 4 cameras of"));
  EXPECT_TRUE(std::regex_search(output, std::regex("CPU path \\(YUYV, [0-9]+ threads\\): stitch "
                                                   "[0-9.]+ ms, chain [0-9.]+ ms = [0-9.]+ fps")))
      << output;
  // Per format: mean / p99 / largest difference from the CPU panorama, then six timings.
  for (const char* format : {"YUYV", "UYVY", "NV12", "BGR"}) {
    std::smatch row;
    ASSERT_TRUE(std::regex_search(
        output, row,
        std::regex(std::string("\n  ") + format +
                   " +([0-9.]+) / +([0-9]+) / +([0-9]+)( +[0-9.]+ \\( *[0-9.]+\\)| +[0-9.]+){5} "
                   "+[0-9.]+x\n")))
        << format << "\n"
        << output;
    EXPECT_LE(std::stod(row[1]), 1.0) << format;
    EXPECT_LE(std::stoi(row[2]), 4) << format;
  }
}

TEST(GpuCheckCli, ABrokenKitIsNamedAndABadCommandLineIsAUsageError) {
  const testing::TempDir dir;
  testing::ChildProcess empty({SURROUND_GPU_CHECK, dir.path().string()}, dir / "out.txt");
  EXPECT_EQ(empty.wait(), 1);
  EXPECT_THAT(empty.output(), HasSubstr("panorama.lut: absent"));

  testing::ChildProcess kit({SURROUND_BENCH, "gpu-kit", (dir / "kits").string(), kRecording},
                            dir / "kit.txt");
  ASSERT_EQ(kit.wait(), 0) << kit.output();
  const auto folder = dir / "kits" / "synth_small";
  std::filesystem::resize_file(folder / "camera2.yuyv", 1000);
  testing::ChildProcess truncated({SURROUND_GPU_CHECK, "--frames", "1", folder.string()},
                                  dir / "out.txt");
  EXPECT_EQ(truncated.wait(), 1);
  EXPECT_THAT(truncated.output(), HasSubstr("camera2.yuyv: expected"));
  std::ofstream(folder / "panorama.lut", std::ios::trunc) << "not a LUT";
  testing::ChildProcess corrupt({SURROUND_GPU_CHECK, folder.string()}, dir / "out.txt");
  EXPECT_EQ(corrupt.wait(), 1);
  EXPECT_THAT(corrupt.output(), HasSubstr("is corrupt (not a LUT file)"));

  testing::ChildProcess none({SURROUND_GPU_CHECK}, dir / "out.txt");
  EXPECT_EQ(none.wait(), 2);
  EXPECT_THAT(none.output(), HasSubstr("no kit folder given"));
  testing::ChildProcess view({SURROUND_GPU_CHECK, "--view", "side", "kit"}, dir / "out.txt");
  EXPECT_EQ(view.wait(), 2);
  EXPECT_THAT(view.output(), HasSubstr("--view needs one of top, 360, orbit, split, rear"));
}

}  // namespace
}  // namespace surroundd
