#pragma once
// surround-bench pipeline: the paper's tables 1 and 2 on the generator's recordings. The whole
// daemon pipeline (decode, sync, stitch, colour correction, surround render, read-back, H.264
// encode) replays each recording as fast as possible; reported are frames per second,
// milliseconds per stage, CPU utilization and peak memory, with the ratio against a baseline run
// in turns with it: the same replay doing only decode and sync (the most any pipeline could do).

#include <filesystem>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/panorama_lut.hpp"
#include "processing/poisson_solver.hpp"
#include "render/view_camera.hpp"

namespace surroundd::bench {

struct PipelineBenchmarkOptions {
  std::vector<std::filesystem::path> recordings;
  int threads = 2;
  int repeats = 3;
  bool json = false;
  processing::PoissonSolverKind solver = processing::PoissonSolverKind::kAuto;
  processing::PanoramaProjection projection = processing::PanoramaProjection::kBowl;
  render::ViewKind view = render::ViewKind::kOrbit;
  cv::Size outputSize{1280, 720};
};

int runPipelineBenchmark(const PipelineBenchmarkOptions& options);

}  // namespace surroundd::bench
