// surround-bench stitch on a small recording: it measures what it says (timings against the
// cv::remap baseline, accuracy for both projections) and prints it as JSON for machines; bad
// command lines are usage errors. surround-bench receive reads a stream as a player would.

#include <array>
#include <chrono>
#include <regex>
#include <thread>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "render/outputs/video_sink.hpp"
#include "tests/support/child_process.hpp"
#include "tests/support/stream_receiver.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd {
namespace {

using ::testing::AllOf;
using ::testing::ContainsRegex;
using ::testing::HasSubstr;

// NOLINTNEXTLINE(cert-err58-cpp): a path made once, before the tests; nothing to catch it.
const std::string kRecording = std::string(SURROUNDD_FIXTURE_DIR) + "/synth_small";

TEST(BenchCli, StitchReportsTimingsAndAccuracyAsJson) {
  const testing::TempDir dir;
  // The JSON on stdout; the log (the pipeline's warnings) on stderr.
  testing::ChildProcess bench({SURROUND_BENCH, "stitch", "--json", "--repeats", "3", kRecording},
                              dir / "log.txt", {}, dir / "out.json");
  ASSERT_EQ(bench.wait(), 0) << bench.output();
  const YAML::Node report = YAML::Load(bench.standardOutput())["stitch"][0];
  EXPECT_EQ(report["input"].as<std::string>(), "synth_small");
  EXPECT_EQ(report["panorama"][0].as<int>(), 512);
  EXPECT_GT(report["lut_build_s"].as<double>(), 0);
  ASSERT_EQ(report["timings"].size(), 2u);  // 1 thread and the default 2
  for (const auto& timing : report["timings"]) {
    EXPECT_GT(timing["stitch_ms"].as<double>(), 0);
    EXPECT_GT(timing["remap_ms"].as<double>(), 0);
    EXPECT_GT(timing["portable_kernels_ms"].as<double>(), 0);
    EXPECT_NEAR(timing["ratio"].as<double>(),
                timing["stitch_ms"].as<double>() / timing["remap_ms"].as<double>(), 1e-3);
  }
  // The top view through its view LUT: a picture like the rendered one (view_lut_test.cpp says
  // why not the same bytes), with both timed.
  const YAML::Node top = report["top_view"];
  EXPECT_EQ(top["size"][0].as<int>(), 1280);
  EXPECT_GT(top["map_ms"].as<double>(), 0);
  EXPECT_GT(top["compose_s"].as<double>(), 0);
  EXPECT_GT(top["view_lut_ms"].as<double>(), 0);
  // The same made in I420 for an encoder, and the encoder's own conversion that spares.
  EXPECT_GT(top["view_lut_i420_ms"].as<double>(), 0);
  EXPECT_GT(top["encoder_bgr_ms"].as<double>(), 0);
  EXPECT_GT(top["rendered_ms"].as<double>(), 0);
  EXPECT_GT(top["psnr_db"].as<double>(), 30.0);
  // Both gathers from the frames held in each format a camera may hand over.
  const std::array<std::string, 4> formats = {"BGR", "YUYV", "UYVY", "NV12"};
  ASSERT_EQ(top["held_formats"].size(), formats.size());
  for (std::size_t f = 0; f < formats.size(); ++f) {
    const YAML::Node held = top["held_formats"][f];
    EXPECT_EQ(held["format"].as<std::string>(), formats[f]);
    EXPECT_GT(held["panorama_ms"].as<double>(), 0);
    EXPECT_GT(held["top_view_ms"].as<double>(), 0);
  }
  EXPECT_LT(report["bowl"]["seam_mean_px"].as<double>(), 0.01);
  EXPECT_GT(report["sphere"]["seam_mean_px"].as<double>(), 3.0);
  EXPECT_LT(report["bowl"]["ground_mae_levels"].as<double>(),
            report["sphere"]["ground_mae_levels"].as<double>());
}

// The pipeline benchmark runs the daemon's pipeline on the recording: every frame set comes out,
// the stage times add up to no more than the run, and the ratio is the one of the two frame rates.
TEST(BenchCli, PipelineReportsFrameRatesStagesAndTheBaselineAsJson) {
  const testing::TempDir dir;
  testing::ChildProcess bench({SURROUND_BENCH, "pipeline", "--json", "--repeats", "1", "--size",
                               "320x240", "--view", "top", kRecording},
                              dir / "log.txt", {}, dir / "out.json");
  ASSERT_EQ(bench.wait(), 0) << bench.output();
  const YAML::Node report = YAML::Load(bench.standardOutput())["pipeline"];
  EXPECT_EQ(report["view"].as<std::string>(), "top");
  EXPECT_THAT(report["renderer"].as<std::string>(), HasSubstr("OpenGL ES 3"));
  const YAML::Node input = report["inputs"][0];
  EXPECT_EQ(input["name"].as<std::string>(), "synth_small");
  EXPECT_EQ(input["frame_sets"].as<int>(), 30);  // the fixture's 1 s at 30 FPS, none lost
  const double fps = input["fps"].as<double>();
  EXPECT_GT(fps, 0);
  EXPECT_NEAR(input["ratio"].as<double>(), fps / input["baseline_fps"].as<double>(), 1e-3);
  double stages = 0;
  for (const char* stage : {"sync", "stitch", "correct", "render", "read-back", "output"}) {
    EXPECT_GE(input["ms"][stage].as<double>(), 0) << stage;
    stages += input["ms"][stage].as<double>();
  }
  EXPECT_GT(input["ms"]["render"].as<double>(), 0);
  EXPECT_GT(input["ms"]["decode"].as<double>(), 0);
  EXPECT_LE(stages, 1000 / fps + 1e-6);
  EXPECT_GT(input["cpu_percent"].as<double>(), 0);
  EXPECT_GT(input["peak_mb"].as<double>(), 10);
  // The figures held to limits: latency, and the start-up of the one run (its LUT built, so cold).
  EXPECT_GT(input["latency_p50_ms"].as<double>(), 0);
  EXPECT_GE(input["latency_p99_ms"].as<double>(), input["latency_p50_ms"].as<double>());
  EXPECT_GT(input["startup_cold_s"].as<double>(), 0);
  EXPECT_FALSE(input["startup_warm_s"]);
}

// --input raw: the recording is preloaded as a camera's frames, and the capture threads' work per
// frame is the conversion to BGR; the report says so, and every set still comes out. The text
// report gives the figures beside their limits.
TEST(BenchCli, PipelineOnRawFramesSaysSoAndReportsTheConversion) {
  const testing::TempDir dir;
  testing::ChildProcess bench(
      {SURROUND_BENCH, "pipeline", "--json", "--repeats", "1", "--size", "320x240", "--view", "top",
       "--input", "raw", "--raw-format", "nv12", kRecording},
      dir / "log.txt", {}, dir / "out.json");
  ASSERT_EQ(bench.wait(), 0) << bench.output();
  const YAML::Node report = YAML::Load(bench.standardOutput())["pipeline"];
  EXPECT_EQ(report["input"].as<std::string>(), "raw-nv12");
  const YAML::Node input = report["inputs"][0];
  EXPECT_EQ(input["frame_sets"].as<int>(), 30);
  EXPECT_GT(input["ms"]["convert"].as<double>(), 0);
  EXPECT_FALSE(input["ms"]["decode"]);
  EXPECT_NEAR(input["ratio"].as<double>(),
              input["fps"].as<double>() / input["baseline_fps"].as<double>(), 1e-3);

  // UYVY cameras, the panorama stitched by OpenGL (llvmpipe here): the report names both.
  testing::ChildProcess gpu(
      {SURROUND_BENCH, "pipeline", "--json", "--repeats", "1", "--size", "320x240", "--input",
       "raw", "--raw-format", "uyvy", "--backend", "gpu", kRecording},
      dir / "gpu-log.txt", {}, dir / "gpu.json");
  ASSERT_EQ(gpu.wait(), 0) << gpu.output();
  const YAML::Node onGpu = YAML::Load(gpu.standardOutput())["pipeline"];
  EXPECT_EQ(onGpu["input"].as<std::string>(), "raw-uyvy");
  EXPECT_THAT(onGpu["renderer"].as<std::string>(), HasSubstr("panorama stitched on the GPU"));
  EXPECT_EQ(onGpu["inputs"][0]["frame_sets"].as<int>(), 30);

  // Two runs: the second reads the LUT the first cached, so the text gives a warm start-up too, and
  // each figure is printed beside its limit.
  testing::ChildProcess text({SURROUND_BENCH, "pipeline", "--repeats", "2", "--size", "320x240",
                              "--view", "top", "--input", "raw", kRecording},
                             dir / "text.txt");
  ASSERT_EQ(text.wait(), 0) << text.output();
  EXPECT_THAT(text.output(), AllOf(HasSubstr("input: raw-yuyv"), HasSubstr("convert+sync")));
  EXPECT_THAT(text.output(),
              AllOf(ContainsRegex("synth_small frame rate [0-9.]+ fps \\(ISO 16505 / IEC "
                                  "63033-3: >= 30 fps, (not )?met\\)"),
                    ContainsRegex("synth_small latency capture to output p50 [0-9.]+ ms  p99 "
                                  "[0-9.]+ ms \\(ISO 16505 / IEC 63033-3: p99 < 200 ms, "),
                    ContainsRegex("synth_small first picture [0-9.]+ s after the pipeline started "
                                  "\\(FMVSS 111: <= 2\\.0 s, (not )?met; target <= 1\\.0 s, "
                                  "(not )?met\\); cold LUT cache [0-9.]+ s")));
}

TEST(BenchCli, BadCommandLinesAreUsageErrors) {
  const testing::TempDir dir;
  for (const auto& [arguments, message] :
       {std::pair{std::vector<std::string>{"stitch"}, "no recording given"},
        std::pair{std::vector<std::string>{"stich", kRecording},
                  "expected 'stitch', 'colour', 'pipeline', 'receive', 'gpu-kit' or 'mounts'"},
        std::pair{std::vector<std::string>{"gpu-kit", "kit"},
                  "gpu-kit needs a folder and at least one recording"},
        std::pair{std::vector<std::string>{"receive"}, "no URL given"},
        std::pair{std::vector<std::string>{"receive", "--transport", "sctp", "rtsp://h/s"},
                  "--transport needs udp or tcp"},
        std::pair{std::vector<std::string>{"receive", "--seconds", "0", "rtsp://h/s"},
                  "--seconds needs a number from 1 to 86400"},
        std::pair{std::vector<std::string>{"pipeline", "--view", "side", kRecording},
                  "--view needs one of top, 360, orbit, split, rear"},
        std::pair{std::vector<std::string>{"pipeline", "--size", "641x480", kRecording},
                  "--size needs an even WIDTHxHEIGHT"},
        std::pair{std::vector<std::string>{"pipeline", "--input", "h264", kRecording},
                  "--input needs decode or raw"},
        std::pair{std::vector<std::string>{"pipeline", "--input", "raw", "--raw-format", "mjpeg",
                                           kRecording},
                  "--raw-format needs yuyv, uyvy or nv12"},
        std::pair{std::vector<std::string>{"pipeline", "--backend", "vulkan", kRecording},
                  "--backend needs auto, cpu or gpu"},
        std::pair{std::vector<std::string>{"pipeline", "--raw-format", "nv12", kRecording},
                  "--raw-format goes with --input raw"},
        std::pair{std::vector<std::string>{"stitch", "--threads", "0", kRecording},
                  "--threads needs a number from 1 to 256"},
        std::pair{std::vector<std::string>{"stitch", "--fast", kRecording},
                  "unknown option '--fast'"},
        std::pair{std::vector<std::string>{"mounts"}, "mounts: no recording given"}}) {
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
  testing::ChildProcess noMounts({SURROUND_BENCH, "mounts", (dir / "nothing").string()},
                                 dir / "out.txt");
  EXPECT_EQ(noMounts.wait(), 1);
  EXPECT_THAT(noMounts.output(), HasSubstr("surround-bench mounts: "));
  testing::ChildProcess http({SURROUND_BENCH, "receive", "http://127.0.0.1:9/"}, dir / "out.txt");
  EXPECT_EQ(http.wait(), 1);
  EXPECT_THAT(
      http.output(),
      HasSubstr("expected rtsp://HOST:PORT/NAME or udp://HOST:PORT, got 'http://127.0.0.1:9/'"));
}

// surround-bench receive watching a network stream as a player: every picture counted, and the
// capture times the stream carries (set here 40 ms before each picture is sent) read back as
// latency.
TEST(BenchCli, ReceiveReportsPicturesAndCaptureToPictureOfAStream) {
  const testing::TempDir dir;
  const int port = testing::freeUdpPort();
  testing::ChildProcess receive(
      {SURROUND_BENCH, "receive", "--seconds", "20", "--save", (dir / "last.png").string(),
       fmt::format("udp://127.0.0.1:{}", port)},
      dir / "out.txt");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!testing::udpPortBound(port) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(testing::udpPortBound(port)) << receive.output();
  const cv::Size size(320, 240);
  render::VideoEncoderSettings settings;
  settings.url = fmt::format("udp://127.0.0.1:{}", port);
  settings.size = size;
  settings.stampCaptureTime = true;
  {
    render::VideoSink sink(settings);
    for (int i = 0; i < 45; ++i) {
      sink.consume(testing::syntheticPicture(size, i),
                   {std::chrono::milliseconds(33 * i),
                    std::chrono::system_clock::now() - std::chrono::milliseconds(40)});
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    sink.finish({}, {});
  }
  // It ends when nothing has come for its 5 s.
  EXPECT_EQ(receive.wait(), 0) << receive.output();
  EXPECT_THAT(receive.output(),
              AllOf(HasSubstr("pictures           45 (320x240)"),
                    HasSubstr("(45 stamped; ISO 16505 / IEC 63033-3: p99 < 200 ms")));
  // At least the 40 ms the stamps say, plus what sending and decoding took.
  std::smatch p50;
  const std::string output = receive.output();
  ASSERT_TRUE(std::regex_search(output, p50, std::regex("capture to picture p50 ([0-9.]+) ms")));
  EXPECT_GE(std::stod(p50[1]), 40.0);
  EXPECT_LT(std::stod(p50[1]), 1000.0);
  EXPECT_EQ(cv::imread((dir / "last.png").string()).size(), size);
}

}  // namespace
}  // namespace surroundd
