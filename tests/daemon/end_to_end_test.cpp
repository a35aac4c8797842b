// surroundd as a user runs it: replay a generated recording, decode the MP4 it wrote and compare it
// with the mosaic of the source frames; stop it with SIGTERM; give it a bad config.

#include <thread>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "capture/file_source.hpp"
#include "common/work_pool.hpp"
#include "daemon/panorama_setup.hpp"
#include "daemon/rig_yaml.hpp"
#include "processing/poisson_correction.hpp"
#include "processing/stitcher.hpp"
#include "render/mosaic.hpp"
#include "tests/support/child_process.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd {
namespace {

using ::testing::HasSubstr;

const std::filesystem::path kRecording =
    std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_small";
const cv::Size kOutputSize(640, 360);

std::filesystem::path writeConfig(const testing::TempDir& dir, std::string_view extra = "") {
  return dir.write("config.yaml", fmt::format(R"(rig: {{file: {}}}
render: {{width_px: {}, height_px: {}}}
outputs:
  - {{type: video, path: out/mosaic.mp4, crf: 16}}
  - {{type: snapshot, path: out/mosaic.png, at_s: 0.5}}
{})",
                                              (kRecording / "rig.yaml").string(), kOutputSize.width,
                                              kOutputSize.height, extra));
}

TEST(EndToEnd, MosaicVideoMatchesTheSourceFrames) {
  const testing::TempDir dir;
  testing::ChildProcess surroundd({SURROUNDD_EXECUTABLE, "--config", writeConfig(dir).string(),
                                   "--pacing", "as_fast_as_possible"},
                                  dir / "log.txt");
  ASSERT_EQ(surroundd.wait(), 0) << surroundd.output();

  const auto rig = daemon::loadRigFile(kRecording / "rig.yaml");
  std::vector<std::string> names;
  std::vector<std::vector<cv::Mat>> sources;
  for (const auto& camera : rig) {
    names.push_back(camera.calibration.name);
    sources.push_back(testing::decodeAll(camera.source->path).images);
  }
  const auto video = testing::decodeAll(dir / "out/mosaic.mp4").images;
  ASSERT_EQ(video.size(),
            sources[0].size());  // one frame set per frame: the recording drops nothing

  const render::Mosaic mosaic(kOutputSize, names);
  cv::Mat expected(kOutputSize, CV_8UC3);
  for (const std::size_t k : {std::size_t{0}, video.size() / 2, video.size() - 1}) {
    std::vector<const cv::Mat*> frames;
    for (const auto& camera : sources) frames.push_back(&camera[k]);
    mosaic.compose(frames, expected);
    EXPECT_GE(cv::PSNR(expected, video[k]), 35.0) << "frame " << k;
  }

  const cv::Mat snapshot = cv::imread((dir / "out/mosaic.png").string());
  EXPECT_EQ(snapshot.size(), kOutputSize);
  for (const auto& entry : std::filesystem::directory_iterator(dir / "out")) {
    EXPECT_NE(entry.path().extension(), ".part") << entry.path();
  }
  EXPECT_THAT(surroundd.output(), HasSubstr("wrote video"));
}

// The panorama output: the video shows the colour-corrected stitch of the source frames; the LUT is
// built on the first run, loaded on the next, and rebuilt when its cache file is damaged.
TEST(EndToEnd, PanoramaVideoMatchesTheStitchedSourceFramesAndTheLutIsCached) {
  const testing::TempDir dir;
  const auto config = dir.write("config.yaml", fmt::format(R"(rig: {{file: {}}}
capture: {{pacing: as_fast_as_possible}}
pipeline: {{threads: 2}}
panorama: {{width_px: 512, height_px: 256, cache_dir: lut-cache}}
outputs:
  - {{type: video, stream: panorama, path: out/panorama.mp4, crf: 12}}
  - {{type: snapshot, stream: panorama, path: out/panorama.png, at_s: 0.5}}
)",
                                                           (kRecording / "rig.yaml").string()));
  const auto run = [&](std::string_view expectedLog) {
    testing::ChildProcess surroundd({SURROUNDD_EXECUTABLE, "--config", config.string()},
                                    dir / "log.txt");
    EXPECT_EQ(surroundd.wait(), 0) << surroundd.output();
    EXPECT_THAT(surroundd.output(), HasSubstr(expectedLog));
  };
  run("panorama LUT 512x256 (bowl projection): building");
  run("panorama LUT 512x256: loaded");
  const auto cached = *std::filesystem::directory_iterator(dir / "lut-cache");
  std::filesystem::resize_file(cached.path(), 1000);
  run("is corrupt (checksum mismatch); rebuilding");

  const daemon::Config loaded = daemon::loadConfig(config);
  WorkPool pool(2);
  const processing::PanoramaLut lut = daemon::obtainPanoramaLut(loaded, pool);
  processing::Stitcher stitcher(lut, pool);
  std::vector<std::vector<cv::Mat>> sources;
  for (const auto& camera : loaded.cameras) {
    sources.push_back(testing::decodeAll(camera.source->path).images);
  }
  const auto video = testing::decodeAll(dir / "out/panorama.mp4").images;
  ASSERT_EQ(video.size(), sources[0].size());
  cv::Mat expected;
  for (const std::size_t k : {std::size_t{0}, video.size() - 1}) {
    std::vector<cv::Mat> frames;
    for (const auto& camera : sources) frames.push_back(camera[k]);
    stitcher.stitch(frames, expected);
    // The config's default colour correction (Poisson), solved for this frame on its own.
    processing::PoissonColourCorrection correction(
        daemon::rigOf(loaded), daemon::panoramaSettings(loaded), lut,
        {loaded.colour.scale, loaded.colour.solver, loaded.colour.tolerance, 0.0}, pool);
    correction.update(frames);
    correction.apply(expected);
    EXPECT_GE(cv::PSNR(expected, video[k]), 35.0) << "frame " << k;
  }
  EXPECT_EQ(cv::imread((dir / "out/panorama.png").string()).size(), lut.size);
}

TEST(EndToEnd, SigtermLeavesAPlayableFile) {
  const testing::TempDir dir;
  testing::ChildProcess surroundd({SURROUNDD_EXECUTABLE, "--config", writeConfig(dir).string()},
                                  dir / "log.txt");
  // Once the cameras are open (logged) the signal handlers are in place; then stop mid-recording.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (surroundd.output().find("camera 'left'") == std::string::npos &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  surroundd.signal(SIGTERM);
  ASSERT_EQ(surroundd.wait(), 0) << surroundd.output();
  const auto frames = testing::decodeAll(dir / "out/mosaic.mp4").images;
  EXPECT_GE(frames.size(), 1u);
  EXPECT_FALSE(std::filesystem::exists(dir / "out/mosaic.mp4.part"));
  EXPECT_TRUE(
      std::filesystem::exists(dir / "out/mosaic.png"));  // the last frame, as the run was short
}

TEST(EndToEnd, BadConfigOpensNothing) {
  const testing::TempDir dir;
  testing::ChildProcess surroundd(
      {SURROUNDD_EXECUTABLE, "--config", writeConfig(dir, "capture: {queue_frames: 0}").string()},
      dir / "log.txt");
  EXPECT_EQ(surroundd.wait(), 2);
  EXPECT_THAT(surroundd.output(),
              HasSubstr("config.yaml:6:25: capture.queue_frames: expected a whole number"));
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(EndToEnd, UnknownOptionIsAUsageError) {
  const testing::TempDir dir;
  testing::ChildProcess surroundd({SURROUNDD_EXECUTABLE, "--confg", "x.yaml"}, dir / "log.txt");
  EXPECT_EQ(surroundd.wait(), 2);
  EXPECT_THAT(surroundd.output(), HasSubstr("unknown option '--confg'"));
}

}  // namespace
}  // namespace surroundd
