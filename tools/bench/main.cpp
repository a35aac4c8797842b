// surround-bench: the project's benchmarks. Each prints frames per second and per-stage
// milliseconds, with ratios against a baseline measured in the same run.
//
//   surround-bench stitch [--threads N] [--repeats N] [--json] RECORDING...
//   surround-bench colour [--threads N] [--repeats N] [--pictures DIR] RECORDING|CONFIG...
//   surround-bench pipeline [--threads N] [--repeats N] [--json] [--solver S] [--projection P]
//                           [--view V] [--size WxH] [--input decode|raw] [--raw-format F]
//                           [--backend B] [--output O] RECORDING...
//   surround-bench receive [--transport udp|tcp] [--seconds N] [--save PICTURE] URL
//   surround-bench gpu-kit KIT RECORDING...
//   surround-bench mounts RECORDING...
//
// Exit codes: 0 done, 1 failed while measuring, 2 bad command line.

#include <charconv>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <string_view>

#include <fmt/format.h>

#include "common/build_info.hpp"
#include "common/work_pool.hpp"
#include "daemon/outputs/built_in_outputs.hpp"
#include "tools/bench/colour_benchmark.hpp"
#include "tools/bench/gpu_kit.hpp"
#include "tools/bench/mount_benchmark.hpp"
#include "tools/bench/pipeline_benchmark.hpp"
#include "tools/bench/receive_benchmark.hpp"
#include "tools/bench/rig_colour_report.hpp"
#include "tools/bench/stitch_benchmark.hpp"

namespace {

constexpr std::string_view kUsage =
    R"(usage: surround-bench stitch [--threads N] [--repeats N] [--json] RECORDING...
       surround-bench colour [--threads N] [--repeats N] [--pictures DIR] RECORDING|CONFIG...
       surround-bench pipeline [--threads N] [--repeats N] [--json] [--solver S]
                               [--projection P] [--view V] [--size WxH] [--input I]
                               [--raw-format F] [--backend B] [--output O] RECORDING...
       surround-bench receive [--transport T] [--seconds N] [--save PICTURE] URL
       surround-bench gpu-kit KIT RECORDING...
       surround-bench mounts RECORDING...
  stitch        LUT build, stitch against cv::remap, accuracy against the ground truth
  colour        Poisson colour correction: solvers, per-frame cost, seam colour error; for a
                CONFIG (a surroundd .yaml: any rig, the shared real ones, your own car): per
                seam the ground misalignment and the colour step on near and far ground with
                no correction, gains and Poisson, and the mean level
  pipeline      the whole daemon pipeline (the paper's tables 1 and 2): frames per second,
                milliseconds per stage, CPU and peak memory, against a decode-only replay
                (--input raw: copy-only); frame rate, latency and time to the first picture
                (cold and warm LUT cache) beside their limits
  receive       a surroundd stream watched as a viewer would (FFmpeg): pictures per second and
                capture to decoded picture, from the capture times the stream carries
  gpu-kit       writes into the folder KIT, per recording, its panorama LUT and first frame set
                as raw YUYV: what surround-gpu-check measures on a machine with a GPU
                (scripts/gpu-check.sh)
  mounts        the calibration watch's mount refinement at the daemon's cadence over drives
                (surround-synth --turn knocks a camera): how long after the turn a correction
                came, how close to the mount after it, false alarms, CPU per compared set
  RECORDING     a surround-synth recording folder (with ground truth); scripts/bench.sh makes
                4x480p, 720p and 1080p ones
  --threads N   worker threads (default 2); stitch measures 1 thread too
  --repeats N   timed runs per candidate, median reported (default 30; pipeline 3)
  --json        stitch, pipeline: one JSON object on stdout instead of the text table
  --solver S    pipeline: auto | cholmod | iterative (default auto)
  --projection P  pipeline: bowl | sphere (default bowl)
  --view V      pipeline: top | 360 | orbit | split | rear (default orbit)
  --size WxH    pipeline: output size (default 1280x720)
  --input I     pipeline: decode (each video decoded as it plays: replay figures; the default) |
                raw (decoded once at start into memory as a camera's frames, handed over per
                frame as a V4L2 camera's are, kept in their YUV: live-rig figures)
  --raw-format F  pipeline, --input raw: yuyv | uyvy | nv12 (default yuyv)
  --backend B   pipeline: where the panorama is made, as processing.backend: auto | cpu | gpu
                (default auto: the CPU on a software renderer such as llvmpipe)
  --output O    pipeline: where the view goes: video (H.264, the default) | window (an X
                window on $DISPLAY, each picture read back) | egl-window (the window shown on
                the GPU through EGL, nothing read back)
  --pictures DIR  colour, CONFIG: also write the panoramas (none, gain, Poisson) and body masks
  URL           receive: rtsp://HOST:PORT/NAME (an rtsp output) or udp://HOST:PORT (a network
                output's address, bound here)
  --transport T receive, RTSP: udp (RTP over UDP; the default) | tcp (in the RTSP connection)
  --seconds N   receive: watch for at most N seconds (default 10; the stream may end first)
  --save PICTURE  receive: write the last picture there (.png, .jpg)
)";

int usageError(std::string_view message) {
  fmt::print(stderr, "surround-bench: {}\n{}", message, kUsage);
  return 2;
}

bool parseNumber(std::string_view text, int& value, int low, int high) {
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size() && value >= low && value <= high;
}

bool parseSize(std::string_view text, cv::Size& size) {
  const auto x = text.find('x');
  return x != std::string_view::npos && parseNumber(text.substr(0, x), size.width, 64, 7680) &&
         parseNumber(text.substr(x + 1), size.height, 64, 4320) && size.width % 2 == 0 &&
         size.height % 2 == 0;
}

template <typename E>
std::optional<E> parseWord(std::string_view text,
                           std::initializer_list<std::pair<std::string_view, E>> words) {
  for (const auto& [word, value] : words) {
    if (word == text) return value;
  }
  return std::nullopt;
}

int receive(int argc, char** argv) {
  surroundd::bench::ReceiveBenchmarkOptions options;
  for (int i = 2; i < argc; ++i) {
    const std::string_view arg = argv[i];
    const std::string_view value = i + 1 < argc ? argv[i + 1] : "";
    if (arg == "--transport") {
      if (value != "udp" && value != "tcp") return usageError("--transport needs udp or tcp");
      options.viewer.transport = value;
      ++i;
    } else if (arg == "--seconds") {
      int seconds = 0;
      if (!parseNumber(value, seconds, 1, 86400)) {
        return usageError("--seconds needs a number from 1 to 86400");
      }
      options.duration = std::chrono::seconds(seconds);
      ++i;
    } else if (arg == "--save") {
      if (value.empty()) return usageError("--save needs a file");
      options.lastPicture = value;
      ++i;
    } else if (arg.starts_with("--")) {
      return usageError(fmt::format("unknown option '{}'", arg));
    } else if (!options.viewer.url.empty()) {
      return usageError("receive takes one URL");
    } else {
      options.viewer.url = arg;
    }
  }
  if (options.viewer.url.empty()) return usageError("no URL given");
  try {
    return surroundd::bench::runReceiveBenchmark(options);
  } catch (const std::exception& e) {
    fmt::print(stderr, "surround-bench: {}\n", e.what());
    return 1;
  }
}

int gpuKit(int argc, char** argv) {
  if (argc < 4) return usageError("gpu-kit needs a folder and at least one recording");
  try {
    surroundd::WorkPool pool(2);
    for (int i = 3; i < argc; ++i) surroundd::bench::writeGpuKit(argv[i], argv[2], pool);
  } catch (const std::exception& e) {
    fmt::print(stderr, "surround-bench: {}\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  namespace bench = surroundd::bench;
  using surroundd::capture::PixelLayout;
  using surroundd::processing::PanoramaProjection;
  using surroundd::processing::PoissonSolverKind;
  using surroundd::render::ViewKind;
  surroundd::daemon::registerBuiltInOutputTypes();  // the pipeline's benchmarks read configs
  if (argc >= 2 && (std::string_view(argv[1]) == "--help" || std::string_view(argv[1]) == "-h")) {
    fmt::print("{}", kUsage);
    return 0;
  }
  if (argc >= 2 && std::string_view(argv[1]) == "--version") {
    fmt::print("{}", surroundd::versionText("surround-bench"));
    return 0;
  }
  const std::string_view command = argc >= 2 ? argv[1] : "";
  if (command == "receive") return receive(argc, argv);
  if (command == "gpu-kit") return gpuKit(argc, argv);
  if (command == "mounts") {
    if (argc < 3) return usageError("mounts: no recording given");
    return bench::runMountBenchmark({argv + 2, argv + argc});
  }
  if (command != "stitch" && command != "colour" && command != "pipeline") {
    return usageError("expected 'stitch', 'colour', 'pipeline', 'receive', 'gpu-kit' or 'mounts'");
  }
  bench::StitchBenchmarkOptions options;
  bench::PipelineBenchmarkOptions pipeline;
  std::optional<int> repeats;
  std::filesystem::path pictures;
  bool rawFormat = false;  // --raw-format given
  for (int i = 2; i < argc; ++i) {
    const std::string_view arg = argv[i];
    const bool hasValue = i + 1 < argc;
    const std::string_view value = hasValue ? argv[i + 1] : "";
    if (arg == "--json") {
      options.json = true;
    } else if (arg == "--threads" || arg == "--repeats") {
      int number = 0;
      if (!hasValue || !parseNumber(value, number, 1, 256)) {
        return usageError(fmt::format("{} needs a number from 1 to 256", arg));
      }
      (arg == "--threads" ? options.threads : repeats.emplace()) = number;
      ++i;
    } else if (command == "pipeline" && arg == "--solver") {
      const auto solver =
          parseWord<PoissonSolverKind>(value, {{"auto", PoissonSolverKind::kAuto},
                                               {"cholmod", PoissonSolverKind::kCholmod},
                                               {"iterative", PoissonSolverKind::kIterative}});
      if (!solver) return usageError("--solver needs auto, cholmod or iterative");
      pipeline.solver = *solver;
      ++i;
    } else if (command == "pipeline" && arg == "--projection") {
      const auto projection = parseWord<PanoramaProjection>(
          value, {{"bowl", PanoramaProjection::kBowl}, {"sphere", PanoramaProjection::kSphere}});
      if (!projection) return usageError("--projection needs bowl or sphere");
      pipeline.projection = *projection;
      ++i;
    } else if (command == "pipeline" && arg == "--view") {
      const auto view = surroundd::render::parseViewKind(value);
      if (!view) return usageError("--view needs one of " + surroundd::render::viewNameList(", "));
      pipeline.view = *view;
      ++i;
    } else if (command == "pipeline" && arg == "--input") {
      const auto input = parseWord<bench::BenchInput>(
          value, {{"decode", bench::BenchInput::kDecode}, {"raw", bench::BenchInput::kRaw}});
      if (!input) return usageError("--input needs decode or raw");
      pipeline.input = *input;
      ++i;
    } else if (command == "pipeline" && arg == "--raw-format") {
      const auto format = parseWord<PixelLayout>(value, {{"yuyv", PixelLayout::kYuyv},
                                                         {"uyvy", PixelLayout::kUyvy},
                                                         {"nv12", PixelLayout::kNv12}});
      if (!format) return usageError("--raw-format needs yuyv, uyvy or nv12");
      pipeline.rawFormat = *format;
      rawFormat = true;
      ++i;
    } else if (command == "pipeline" && arg == "--backend") {
      using surroundd::daemon::ProcessingBackend;
      const auto backend = parseWord<ProcessingBackend>(value, {{"auto", ProcessingBackend::kAuto},
                                                                {"cpu", ProcessingBackend::kCpu},
                                                                {"gpu", ProcessingBackend::kGpu}});
      if (!backend) return usageError("--backend needs auto, cpu or gpu");
      pipeline.backend = *backend;
      ++i;
    } else if (command == "pipeline" && arg == "--output") {
      using surroundd::bench::BenchOutput;
      const auto output = parseWord<BenchOutput>(value, {{"video", BenchOutput::kVideo},
                                                         {"window", BenchOutput::kWindow},
                                                         {"egl-window", BenchOutput::kEglWindow}});
      if (!output) return usageError("--output needs video, window or egl-window");
      pipeline.output = *output;
      ++i;
    } else if (command == "colour" && arg == "--pictures") {
      if (!hasValue) return usageError("--pictures needs a folder");
      pictures = value;
      ++i;
    } else if (command == "pipeline" && arg == "--size") {
      if (!parseSize(value, pipeline.outputSize)) {
        return usageError("--size needs an even WIDTHxHEIGHT such as 1280x720");
      }
      ++i;
    } else if (arg.starts_with("--")) {
      return usageError(fmt::format("unknown option '{}'", arg));
    } else {
      options.recordings.emplace_back(arg);
    }
  }
  if (options.recordings.empty()) return usageError("no recording given");
  if (rawFormat && pipeline.input != bench::BenchInput::kRaw) {
    return usageError("--raw-format goes with --input raw");
  }
  if (repeats) options.repeats = *repeats;
  try {
    if (command == "colour") {
      bench::ColourBenchmarkOptions colour{{}, options.threads, options.repeats};
      for (const auto& input : options.recordings) {
        if (std::filesystem::is_regular_file(input)) {
          surroundd::WorkPool pool(options.threads);
          bench::reportRigColour(bench::rigColourInput(input, pool), pool, pictures);
        } else {
          colour.recordings.push_back(input);
        }
      }
      return colour.recordings.empty() ? 0 : bench::runColourBenchmark(colour);
    }
    if (command == "pipeline") {
      pipeline.recordings = options.recordings;
      pipeline.threads = options.threads;
      pipeline.repeats = repeats.value_or(pipeline.repeats);
      pipeline.json = options.json;
      return bench::runPipelineBenchmark(pipeline);
    }
    return bench::runStitchBenchmark(options);
  } catch (const std::exception& e) {
    fmt::print(stderr, "surround-bench: {}\n", e.what());
    return 1;
  }
}
