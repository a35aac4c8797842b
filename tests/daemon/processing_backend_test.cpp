// processing.backend in the pipeline. On the GPU backend (here on llvmpipe) the surround views are
// drawn from the panorama the GPU stitched from the frames as they were held, and show what the
// CPU path shows: every view within PSNR 40 dB, for frames decoded (BGR) or preloaded as YUYV and
// NV12. A set with a faulty camera is made on the CPU, its part marked as the CPU path marks it.
// auto keeps a software renderer on the CPU, gain compensation stays there, and each choice is
// logged with its reason. The report has the GPU's own time of each step it ran.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "daemon/pipeline.hpp"
#include "daemon/pipeline_report.hpp"
#include "tests/daemon/config/config_test_support.hpp"
#include "tests/daemon/replay_config.hpp"
#include "tests/support/log_capture.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd::daemon {
namespace {

using std::chrono::nanoseconds;
using ::testing::AllOf;
using ::testing::Contains;
using ::testing::HasSubstr;
using ::testing::Not;

TEST_F(ConfigTest, TheBackendIsReadAndABadOneNamed) {
  EXPECT_EQ(loadConfig(configWith("logging:", "logging:")).processing.backend,
            ProcessingBackend::kAuto);
  for (const auto& [word, backend] :
       {std::pair{"cpu", ProcessingBackend::kCpu}, std::pair{"gpu", ProcessingBackend::kGpu},
        std::pair{"auto", ProcessingBackend::kAuto}}) {
    const auto file =
        configWith("logging:", std::string("processing: {backend: ") + word + "}\nlogging:");
    EXPECT_EQ(loadConfig(file).processing.backend, backend) << word;
  }
  expectOneError(
      "logging:", "processing: {backend: vulkan}\nlogging:",
      {where(1, 23), "processing.backend: expected one of 'auto' 'cpu' 'gpu'", "'vulkan'"});
}

constexpr std::array kViews{ViewKind::kOrbit, ViewKind::kTop, ViewKind::kPanorama360,
                            ViewKind::kSplit};

struct BackendRun {
  std::vector<cv::Mat> pictures;  // per snapshot, in the order asked
  std::vector<std::string> log;
  RunSummary summary;
};

// `config` run with each (view, time) snapshot of the surround stream.
BackendRun runWith(Config config, const std::filesystem::path& dir,
                   const std::vector<std::pair<ViewKind, double>>& snapshots) {
  config.outputs.clear();
  for (std::size_t i = 0; i < snapshots.size(); ++i) {
    OutputConfig snapshot = snapshotAt(dir / ("snapshot" + std::to_string(i) + ".png"),
                                       OutputStream::kSurround, snapshots[i].second);
    snapshot.view = snapshots[i].first;
    config.outputs.push_back(snapshot);
  }
  BackendRun run;
  {
    const testing::LogCapture log;
    Pipeline pipeline(config);
    const std::atomic<bool> stop{false};
    run.summary = pipeline.run(stop);
    run.log = log.lines();
  }
  for (std::size_t i = 0; i < snapshots.size(); ++i) {
    run.pictures.push_back(cv::imread((dir / ("snapshot" + std::to_string(i) + ".png")).string()));
  }
  return run;
}

class ProcessingBackendTest : public ::testing::Test {
 protected:
  // At the default panorama size, where a fixed view gathered through its own table matches its
  // OpenGL drawing within 40 dB (render.view_lut); a small one is enough where both paths draw
  // with OpenGL.
  Config replayOf(const std::string& fixture, bool smallPanorama) {
    Config config = fixtureReplay(fixture, {});
    config.pipeline.threads = 2;
    config.panorama.cacheDir = dir_ / "lut-cache";
    if (smallPanorama) useSmallPanorama(config, dir_ / "small-lut-cache");
    return config;
  }
  BackendRun runOn(Config config, ProcessingBackend backend,
                   const std::vector<std::pair<ViewKind, double>>& snapshots) {
    config.processing.backend = backend;
    const auto folder = dir_ / std::to_string(runs_++);
    std::filesystem::create_directories(folder);
    return runWith(std::move(config), folder, snapshots);
  }

  testing::TempDir dir_;
  int runs_ = 0;
};

TEST_F(ProcessingBackendTest, EveryViewFromTheGpuStitchIsTheCpuPathsPicture) {
  std::vector<std::pair<ViewKind, double>> snapshots(kViews.size());
  std::ranges::transform(kViews, snapshots.begin(), [](ViewKind view) {
    return std::pair{view, 0.5};
  });
  // Decoded frames (BGR) and preloaded NV12 (two planes); YUYV in the test below.
  for (const auto preload :
       {std::optional<capture::PixelLayout>{}, std::optional{capture::PixelLayout::kNv12}}) {
    const char* const held = preload ? capture::toString(*preload) : "BGR";
    SCOPED_TRACE(held);
    Config config = replayOf("synth_small", false);
    for (auto& camera : config.cameras) camera.preload(preload);
    const BackendRun cpu = runOn(config, ProcessingBackend::kCpu, snapshots);
    const BackendRun gpu = runOn(config, ProcessingBackend::kGpu, snapshots);
    EXPECT_THAT(cpu.log, Contains(HasSubstr("processing: cpu (processing.backend: cpu)")));
    EXPECT_THAT(gpu.log, Contains(AllOf(HasSubstr("processing: gpu (processing.backend: gpu, on a "
                                                  "renderer that runs on the CPU"),
                                        HasSubstr(std::string("frames uploaded as ")))));
    EXPECT_THAT(gpu.summary.renderer, HasSubstr("panorama stitched on the GPU"));
    EXPECT_THAT(cpu.summary.renderer, Not(HasSubstr("GPU")));
    EXPECT_EQ(gpu.summary.frameSets, cpu.summary.frameSets);
    for (std::size_t i = 0; i < kViews.size(); ++i) {
      SCOPED_TRACE(toString(kViews[i]));
      ASSERT_FALSE(cpu.pictures[i].empty());
      ASSERT_EQ(gpu.pictures[i].size(), cpu.pictures[i].size());
      // Not a picture of nothing: the panorama shows in it.
      EXPECT_GT(cv::mean(gpu.pictures[i])[1], 20.0);
      EXPECT_GE(cv::PSNR(gpu.pictures[i], cpu.pictures[i]), 40.0);
    }
  }
}

// From 0.5 s 'left' is frozen, 'right' black and 'back' stopped (the synth_faults recording,
// preloaded as YUYV): those sets are stitched on the CPU, which marks the faulty cameras' parts;
// before, the GPU stitches. Either way the picture is the CPU path's. Both draw with OpenGL here
// (no view tables): the marks' stripes are drawn in the panorama, so a view gathered through its
// own table shows them at other places.
TEST_F(ProcessingBackendTest, ASetWithAFaultyCameraIsMadeOnTheCpuAndMarked) {
  const std::vector<std::pair<ViewKind, double>> snapshots{{ViewKind::kTop, 0.3},
                                                           {ViewKind::kTop, 0.9}};
  Config config = replayOf("synth_faults", true);
  config.render.viewLut = false;
  for (auto& camera : config.cameras) camera.preload(capture::PixelLayout::kYuyv);
  const BackendRun cpu = runOn(config, ProcessingBackend::kCpu, snapshots);
  const BackendRun gpu = runOn(config, ProcessingBackend::kGpu, snapshots);
  EXPECT_THAT(gpu.summary.renderer, HasSubstr("panorama stitched on the GPU"));
  ASSERT_EQ(gpu.pictures.size(), 2u);
  for (std::size_t i = 0; i < snapshots.size(); ++i) {
    SCOPED_TRACE(snapshots[i].second);
    ASSERT_FALSE(gpu.pictures[i].empty());
    EXPECT_GE(cv::PSNR(gpu.pictures[i], cpu.pictures[i]), 40.0);
  }
  // The marks are there to be seen: the faulty set's picture is far from the healthy one's.
  EXPECT_LT(cv::PSNR(gpu.pictures[1], gpu.pictures[0]), 30.0);
}

TEST_F(ProcessingBackendTest, AutoAndGainCompensationKeepTheCpuAndSayWhy) {
  const std::vector<std::pair<ViewKind, double>> snapshots{{ViewKind::kOrbit, 0.1}};
  Config config = replayOf("synth_small", true);
  const BackendRun automatic = runOn(config, ProcessingBackend::kAuto, snapshots);
  EXPECT_THAT(automatic.log,
              Contains(HasSubstr("processing: cpu (auto: the renderer runs on the CPU, where "
                                 "the CPU path is faster)")));
  config.colour.method = ColourMethod::kGain;
  const BackendRun gains = runOn(config, ProcessingBackend::kGpu, snapshots);
  EXPECT_THAT(
      gains.log,
      Contains(HasSubstr("processing: cpu (gain compensation is applied on the CPU only)")));
  EXPECT_THAT(gains.summary.renderer, Not(HasSubstr("GPU")));
}

// The GPU's own time of each step it ran, in the report and the status: on the GPU backend the
// frames' upload, the stitch pass, the view's draw and read-back; on the CPU backend the
// panorama's upload, the draw and read-back, no stitch. An orbit video draws every set.
TEST_F(ProcessingBackendTest, TheReportHasTheGpusOwnTimeOfEachStepItRan) {
  Config config = replayOf("synth_small", true);
  for (auto& camera : config.cameras) camera.preload(capture::PixelLayout::kYuyv);
  OutputConfig orbit = videoOutputAt(dir_ / "orbit.mkv");
  orbit.stream = OutputStream::kSurround;
  orbit.view = ViewKind::kOrbit;
  config.outputs = {orbit};
  for (const auto backend : {ProcessingBackend::kGpu, ProcessingBackend::kCpu}) {
    const bool gpu = backend == ProcessingBackend::kGpu;
    SCOPED_TRACE(gpu ? "gpu" : "cpu");
    config.processing.backend = backend;
    std::filesystem::remove(dir_ / "orbit.mkv");
    Pipeline pipeline(config);
    const std::atomic<bool> stop{false};
    const RunSummary summary = pipeline.run(stop);
    const PipelineReport& report = summary.report;
    if (!report.gpuTimed) GTEST_SKIP() << "the renderer has no GL_EXT_disjoint_timer_query";
    ASSERT_GT(summary.frameSets, 20u);
    const auto runs = [&](render::GpuStep step) {
      return report.gpuSteps[static_cast<std::size_t>(step)].count();
    };
    // Read a set or two after each run, a few of the last ones after the end: most of them.
    const std::uint64_t most = summary.frameSets - render::GpuTimer::kQueriesPerStep;
    for (const auto step :
         {render::GpuStep::kUpload, render::GpuStep::kDraw, render::GpuStep::kReadBack}) {
      EXPECT_GE(runs(step), most) << render::toString(step);
      EXPECT_LE(runs(step), summary.frameSets + 1) << render::toString(step);  // + the last redraw
      EXPECT_GT(report.gpuSteps[static_cast<std::size_t>(step)].quantile(0.5), nanoseconds(0));
    }
    const std::string status = statusText(report);
    EXPECT_THAT(status, ::testing::ContainsRegex("gpu read-back +p50 +[0-9.]+ ms"));
    if (gpu) {
      EXPECT_GE(runs(render::GpuStep::kStitch), most);
      EXPECT_THAT(status, HasSubstr("gpu stitch "));
    } else {
      EXPECT_EQ(runs(render::GpuStep::kStitch), 0u);
      EXPECT_THAT(status, Not(HasSubstr("gpu stitch ")));
    }
  }
}

}  // namespace
}  // namespace surroundd::daemon
