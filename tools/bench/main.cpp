// surround-bench: the project's benchmarks. Each prints frames per second and per-stage
// milliseconds, with ratios against a baseline measured in the same run.
//
//   surround-bench stitch [--threads N] [--repeats N] [--json] RECORDING...
//   surround-bench colour [--threads N] [--repeats N] RECORDING...
//
// Exit codes: 0 done, 1 failed while measuring, 2 bad command line.

#include <charconv>
#include <cstdio>
#include <exception>
#include <string_view>

#include <fmt/format.h>

#include "tools/bench/colour_benchmark.hpp"
#include "tools/bench/stitch_benchmark.hpp"

namespace {

constexpr std::string_view kUsage =
    R"(usage: surround-bench stitch [--threads N] [--repeats N] [--json] RECORDING...
       surround-bench colour [--threads N] [--repeats N] RECORDING...
  stitch        LUT build, stitch against cv::remap, accuracy against the ground truth
  colour        Poisson colour correction: solvers, per-frame cost, seam colour error
  RECORDING     a surround-synth recording folder (with ground truth); scripts/bench.sh makes
                4x480p, 720p and 1080p ones
  --threads N   threads for the stitcher and cv::remap (default 2); 1 thread is measured too
  --repeats N   timed runs per candidate, median reported (default 30)
  --json        stitch: one JSON object on stdout instead of the text table
)";

int usageError(std::string_view message) {
  fmt::print(stderr, "surround-bench: {}\n{}", message, kUsage);
  return 2;
}

bool parseCount(std::string_view text, int& value) {
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size() && value >= 1 && value <= 256;
}

}  // namespace

int main(int argc, char** argv) {
  using surroundd::bench::StitchBenchmarkOptions;
  if (argc >= 2 && (std::string_view(argv[1]) == "--help" || std::string_view(argv[1]) == "-h")) {
    fmt::print("{}", kUsage);
    return 0;
  }
  const std::string_view command = argc >= 2 ? argv[1] : "";
  if (command != "stitch" && command != "colour") {
    return usageError("expected 'stitch' or 'colour'");
  }
  StitchBenchmarkOptions options;
  for (int i = 2; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--json") {
      options.json = true;
    } else if (arg == "--threads" || arg == "--repeats") {
      int& target = arg == "--threads" ? options.threads : options.repeats;
      if (i + 1 >= argc || !parseCount(argv[++i], target)) {
        return usageError(fmt::format("{} needs a number from 1 to 256", arg));
      }
    } else if (arg.starts_with("--")) {
      return usageError(fmt::format("unknown option '{}'", arg));
    } else {
      options.recordings.emplace_back(arg);
    }
  }
  if (options.recordings.empty()) return usageError("no recording given");
  try {
    if (command == "colour") {
      return surroundd::bench::runColourBenchmark(
          {options.recordings, options.threads, options.repeats});
    }
    return surroundd::bench::runStitchBenchmark(options);
  } catch (const std::exception& e) {
    fmt::print(stderr, "surround-bench: {}\n", e.what());
    return 1;
  }
}
