#include "tools/bench/pipeline_benchmark.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <unistd.h>

#include "daemon/config/logging.hpp"
#include "daemon/config/rig_yaml.hpp"
#include "daemon/outputs/video/video_output.hpp"
#include "daemon/outputs/window/window_output.hpp"
#include "daemon/pipeline.hpp"
#include "render/gpu_timer.hpp"
#include "tools/bench/recording_truth.hpp"

namespace surroundd::bench {
namespace {

// The paper's table 1 (frames per second for 4 x 1080p, 720p, 480p), for orientation only: other
// hardware, not measured here.
constexpr const char* kPaperFigures =
    "paper, table 1: desktop (Xeon E3-1230 + GTX 1070) 50 / 55 / 62 FPS, Jetson AGX Xavier "
    "15 / 18 / 20 FPS for 4 x 1080p / 720p / 480p";

struct RunFigures {
  daemon::RunSummary summary;
  double cpuSeconds = 0;
  double peakMegabytes = 0;
  double fps() const { return summary.framesPerSecond(); }
};

// From the pipeline's construction (cameras and outputs opened, the LUT built or read from the
// cache; with raw input, the recording preloaded) to its first picture handed to the video output.
using Startup = std::chrono::duration<double>;

struct RecordingFigures {
  std::string name;
  cv::Size camera;
  cv::Size panorama;
  RunFigures full;         // the run of median frame rate
  double baselineFps = 0;  // median
  double decodeMs = 0;     // per camera frame, in the capture threads: decode or raw conversion
  Startup coldStartup{0};  // the first full run's: the LUT is built and cached
  std::optional<Startup> warmStartup;  // the median of the later runs': read from the cache
};

Startup startupOf(const RunFigures& run) { return run.summary.report.startup.value_or(Startup{}); }

double cpuSecondsSoFar() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) * 1e-6;
  };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

// Linux keeps the peak resident size (VmHWM); writing 5 to clear_refs starts it afresh.
void resetPeakMemory() { std::ofstream("/proc/self/clear_refs") << "5"; }

double peakMegabytes() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.starts_with("VmHWM:")) return std::stod(line.substr(6)) / 1024;
  }
  return 0;
}

RunFigures runOnce(const daemon::Config& config) {
  daemon::Pipeline pipeline(config);  // LUT (cached), factorizations, GL: start-up, not timed
  resetPeakMemory();
  const double cpuBefore = cpuSecondsSoFar();
  const std::atomic<bool> stop{false};
  RunFigures figures;
  figures.summary = pipeline.run(stop);
  figures.cpuSeconds = cpuSecondsSoFar() - cpuBefore;
  figures.peakMegabytes = peakMegabytes();
  return figures;
}

daemon::Config configFor(const std::filesystem::path& folder, const RecordingTruth& truth,
                         const PipelineBenchmarkOptions& options,
                         const std::filesystem::path& scratch) {
  daemon::Config config;
  config.file = folder / "rig.yaml";
  config.cameras = daemon::loadRigFile(folder / "rig.yaml");
  config.capture.pacing = capture::Pacing::kAsFastAsPossible;
  config.pipeline.threads = options.threads;
  config.panorama.widthPx = truth.panorama.size.width;
  config.panorama.heightPx = truth.panorama.size.height;
  config.panorama.projection = options.projection;
  config.panorama.cacheDir = scratch / "lut-cache";
  config.colour.poisson.solver = options.solver;
  if (options.input == BenchInput::kRaw) {
    for (auto& camera : config.cameras) camera.preload(options.rawFormat);
  }
  config.render.view = options.view;
  config.processing.backend = options.backend;
  config.render.widthPx = options.outputSize.width;
  config.render.heightPx = options.outputSize.height;
  daemon::OutputConfig output;
  output.stream = daemon::OutputStream::kSurround;
  if (options.output == BenchOutput::kVideo) {
    output.path = scratch / "surround.mp4";
    daemon::VideoOutputSettings video;
    video.h264.preset = "ultrafast";
    output.settings = daemon::OutputSettings(video);
  } else {
    output.kind = daemon::OutputKind::kWindow;
    daemon::WindowOutputSettings window;
    window.present = options.output == BenchOutput::kEglWindow ? daemon::ViewPresent::kEgl
                                                               : daemon::ViewPresent::kPicture;
    output.settings = daemon::OutputSettings(window);
  }
  config.outputs = {output};
  return config;
}

RecordingFigures measure(const std::filesystem::path& folder,
                         const PipelineBenchmarkOptions& options,
                         const std::filesystem::path& scratch) {
  const RecordingTruth truth = loadRecordingTruth(folder);
  const daemon::Config full = configFor(folder, truth, options, scratch);
  daemon::Config baseline = full;
  baseline.outputs.clear();  // decode and sync only

  std::vector<RunFigures> fullRuns;
  std::vector<double> baselineFps;
  for (int r = 0; r < options.repeats; ++r) {
    baselineFps.push_back(runOnce(baseline).fps());
    fullRuns.push_back(runOnce(full));
  }
  RecordingFigures figures;
  figures.coldStartup = startupOf(fullRuns.front());
  if (fullRuns.size() > 1) {
    std::vector<Startup> warm;
    for (auto run = fullRuns.begin() + 1; run != fullRuns.end(); ++run) {
      warm.push_back(startupOf(*run));
    }
    std::ranges::sort(warm);
    figures.warmStartup = warm[warm.size() / 2];
  }
  std::ranges::sort(fullRuns, {}, &RunFigures::fps);
  std::ranges::sort(baselineFps);

  figures.name = folder.filename().string();
  figures.camera = truth.rig.cameras.front().intrinsics.imageSize;
  figures.panorama = truth.panorama.size;
  figures.full = fullRuns[fullRuns.size() / 2];
  figures.baselineFps = baselineFps[baselineFps.size() / 2];
  std::chrono::nanoseconds read{0};
  std::uint64_t frames = 0;
  for (const auto& camera : figures.full.summary.cameras) {
    read += camera.readTime;
    frames += camera.frames;
  }
  figures.decodeMs = frames > 0 ? std::chrono::duration<double, std::milli>(read).count() /
                                      static_cast<double>(frames)
                                : 0;
  return figures;
}

double stageMs(const RunFigures& run, daemon::Stage stage) {
  const auto sets = static_cast<double>(std::max<std::uint64_t>(run.summary.frameSets, 1));
  return std::chrono::duration<double, std::milli>(
             run.summary.stageTime[static_cast<std::size_t>(stage)])
             .count() /
         sets;
}

// The median GPU time of a run of `step` (the GPU's own clock); none when it had no run.
std::optional<double> gpuMs(const RunFigures& run, render::GpuStep step) {
  const auto& times = run.summary.report.gpuSteps[static_cast<std::size_t>(step)];
  if (times.count() == 0) return std::nullopt;
  return std::chrono::duration<double, std::milli>(times.quantile(0.5)).count();
}

constexpr std::array kGpuSteps{render::GpuStep::kUpload, render::GpuStep::kStitch,
                               render::GpuStep::kDraw, render::GpuStep::kReadBack};

void printGpuSteps(const std::vector<RecordingFigures>& all) {
  if (!all.front().full.summary.report.gpuTimed) {
    fmt::print("\nGPU steps not timed: the renderer has no GL_EXT_disjoint_timer_query\n");
    return;
  }
  fmt::print(
      "\nGPU milliseconds per run of each step (the GPU's own clock, GL_EXT_disjoint_timer_query; "
      "median; '-': no run)\n{:<8}",
      "input");
  for (const auto step : kGpuSteps) fmt::print(" {:>9}", render::toString(step));
  fmt::print("\n");
  for (const auto& r : all) {
    fmt::print("{:<8}", r.name);
    for (const auto step : kGpuSteps) {
      const auto ms = gpuMs(r.full, step);
      fmt::print(" {:>9}", ms ? fmt::format("{:.2f}", *ms) : "-");
    }
    fmt::print("\n");
  }
}

double cpuPercent(const RunFigures& run, int cores) {
  return 100 * run.cpuSeconds / run.summary.wallTime.count() / cores;
}

constexpr std::array kStages{daemon::Stage::kSync,     daemon::Stage::kStitch,
                             daemon::Stage::kCorrect,  daemon::Stage::kRender,
                             daemon::Stage::kReadBack, daemon::Stage::kOutput};

// The input's name in the report ("decode", "raw-yuyv", "raw-uyvy", "raw-nv12") and what the
// capture threads do per camera frame.
std::string inputName(const PipelineBenchmarkOptions& options) {
  if (options.input == BenchInput::kDecode) return "decode";
  std::string format = capture::toString(options.rawFormat);
  std::ranges::transform(format, format.begin(), [](unsigned char c) { return std::tolower(c); });
  return "raw-" + format;
}
const char* captureWork(const PipelineBenchmarkOptions& options) {
  return options.input == BenchInput::kDecode ? "decode" : "convert";
}

// The figures the standards hold a surround view to, beside their limits. The replay runs as fast
// as it can and waits for its slowest output, so its latency includes the wait in full queues: an
// upper bound of a live rig's, where the newest set wins.
void printAgainstLimits(const std::vector<RecordingFigures>& all,
                        const PipelineBenchmarkOptions& options) {
  fmt::print(
      "\nagainst the limits (the run of median frame rate; the first picture from the pipeline's "
      "start with a warm LUT cache, the first run's cold one beside it{})\n",
      options.input == BenchInput::kRaw ? "; the recordings' preload into memory counts in it"
                                        : "");
  for (const auto& r : all) {
    fmt::print("{:<8} frame rate {}\n", r.name, daemon::frameRateWithLimit(r.full.fps()));
    fmt::print("{:<8} latency capture to output {}\n", r.name,
               daemon::latencyWithLimit(r.full.summary.report.latency));
    const auto from = daemon::StartupFrom::kPipeline;
    if (r.warmStartup) {
      fmt::print("{:<8} first picture {}; cold LUT cache {:.2f} s\n", r.name,
                 daemon::startupWithLimits(*r.warmStartup, from), r.coldStartup.count());
    } else {
      fmt::print("{:<8} first picture (cold LUT cache; warm with --repeats 2 or more) {}\n", r.name,
                 daemon::startupWithLimits(r.coldStartup, from));
    }
  }
}

void printText(const std::vector<RecordingFigures>& all, const PipelineBenchmarkOptions& options,
               int cores) {
  const auto& first = all.front().full.summary;
  fmt::print(
      "surround-bench pipeline: replay as fast as possible; {} projection, colour solver {}, {} "
      "view {}x{}, H.264 ultrafast; {} worker threads on {} cores; renderer {}; medians of {} "
      "runs\n",
      options.projection == processing::PanoramaProjection::kBowl ? "bowl" : "sphere",
      processing::poissonSolverName(options.solver), render::toString(options.view),
      options.outputSize.width, options.outputSize.height, options.threads, cores, first.renderer,
      options.repeats);
  if (options.input == BenchInput::kDecode) {
    fmt::print("input: decode (each camera's H.264 video decoded as it plays)\n");
  } else {
    fmt::print(
        "input: {} (each recording decoded once at start into memory as {} frames, handed over "
        "per frame as a V4L2 camera's are, kept in their YUV; convert: that copy; peak MB "
        "includes them)\n",
        inputName(options), capture::toString(options.rawFormat));
  }
  fmt::print("{:<26} {:>7} {:>13} {:>7} {:>6} {:>8}\n", "input -> panorama", "FPS",
             fmt::format("{}+sync", captureWork(options)), "ratio", "CPU %", "peak MB");
  for (const auto& r : all) {
    fmt::print("{:<26} {:>7.1f} {:>9.1f} FPS {:>6.2f}x {:>6.0f} {:>8.0f}\n",
               fmt::format("4x{}x{} -> {}x{}", r.camera.width, r.camera.height, r.panorama.width,
                           r.panorama.height),
               r.full.fps(), r.baselineFps, r.full.fps() / r.baselineFps, cpuPercent(r.full, cores),
               r.full.peakMegabytes);
  }
  fmt::print(
      "\nmilliseconds per frame set (pipeline thread; {0} runs in parallel, one thread "
      "per camera, and is per camera frame)\n{1:<8} {0:>7}",
      captureWork(options), "input");
  for (const auto stage : kStages) fmt::print(" {:>9}", daemon::toString(stage));
  fmt::print("\n");
  for (const auto& r : all) {
    fmt::print("{:<8} {:>7.2f}", r.name, r.decodeMs);
    for (const auto stage : kStages) fmt::print(" {:>9.2f}", stageMs(r.full, stage));
    fmt::print("\n");
  }
  printGpuSteps(all);
  printAgainstLimits(all, options);
  fmt::print(
      "\n'ratio' is the full pipeline's frame rate over the {}+sync-only replay of the "
      "same recording, run in turns with it.\n{}\n",
      captureWork(options), kPaperFigures);
}

double latencyMs(const RecordingFigures& r, double quantile) {
  return std::chrono::duration<double, std::milli>(r.full.summary.report.latency.quantile(quantile))
      .count();
}

void printJson(const std::vector<RecordingFigures>& all, const PipelineBenchmarkOptions& options,
               int cores) {
  fmt::print(
      "{{\"pipeline\": {{\"threads\": {}, \"cores\": {}, \"repeats\": {}, \"view\": \"{}\", "
      "\"input\": \"{}\", \"renderer\": \"{}\", \"inputs\": [",
      options.threads, cores, options.repeats, render::toString(options.view), inputName(options),
      all.front().full.summary.renderer);
  for (std::size_t i = 0; i < all.size(); ++i) {
    const auto& r = all[i];
    fmt::print(
        "{}\n  {{\"name\": \"{}\", \"camera\": [{}, {}], \"panorama\": [{}, {}], "
        "\"fps\": {:.3f}, \"baseline_fps\": {:.3f}, \"ratio\": {:.4f}, \"cpu_percent\": "
        "{:.1f}, \"peak_mb\": {:.1f}, \"frame_sets\": {}, \"latency_p50_ms\": {:.3f}, "
        "\"latency_p99_ms\": {:.3f}, \"startup_cold_s\": {:.4f}, {}\"ms\": {{\"{}\": {:.3f}",
        i == 0 ? "" : ",", r.name, r.camera.width, r.camera.height, r.panorama.width,
        r.panorama.height, r.full.fps(), r.baselineFps, r.full.fps() / r.baselineFps,
        cpuPercent(r.full, cores), r.full.peakMegabytes, r.full.summary.frameSets,
        latencyMs(r, 0.5), latencyMs(r, 0.99), r.coldStartup.count(),
        r.warmStartup ? fmt::format("\"startup_warm_s\": {:.4f}, ", r.warmStartup->count()) : "",
        captureWork(options), r.decodeMs);
    for (const auto stage : kStages) {
      fmt::print(", \"{}\": {:.3f}", daemon::toString(stage), stageMs(r.full, stage));
    }
    // The GPU's own time per run of each step that ran and could be timed.
    fmt::print("}}, \"gpu_ms\": {{");
    const char* separator = "";
    for (const auto step : kGpuSteps) {
      if (const auto ms = gpuMs(r.full, step)) {
        fmt::print("{}\"{}\": {:.3f}", separator, render::toString(step), *ms);
        separator = ", ";
      }
    }
    fmt::print("}}}}");
  }
  fmt::print("\n]}}}}\n");
}

}  // namespace

int runPipelineBenchmark(const PipelineBenchmarkOptions& options) {
  const auto scratch = std::filesystem::temp_directory_path() /
                       fmt::format("surround-bench-pipeline-{}", ::getpid());
  std::filesystem::create_directories(scratch);
  daemon::setUpLogging(spdlog::level::warn);  // the daemon's warnings and errors, no progress
  std::vector<RecordingFigures> all;
  try {
    for (const auto& folder : options.recordings) {
      if (!options.json) std::fprintf(stderr, "measuring %s ...\n", folder.string().c_str());
      all.push_back(measure(folder, options, scratch));
    }
  } catch (...) {
    std::filesystem::remove_all(scratch);
    throw;
  }
  std::filesystem::remove_all(scratch);
  const int cores = static_cast<int>(std::max(1U, std::thread::hardware_concurrency()));
  if (options.json) {
    printJson(all, options, cores);
  } else {
    printText(all, options, cores);
  }
  return 0;
}

}  // namespace surroundd::bench
