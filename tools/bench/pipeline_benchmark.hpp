#pragma once
// surround-bench pipeline: the paper's tables 1 and 2 on the generator's recordings. The whole
// daemon pipeline (decode, sync, stitch, colour correction, surround render, read-back, H.264
// encode) replays each recording as fast as possible; reported are frames per second,
// milliseconds per stage, CPU utilization and peak memory, with the ratio against a baseline run
// in turns with it: the same replay doing only decode and sync (the most any pipeline could do);
// and the frame rate, capture-to-output latency and time to the first picture (cold and warm LUT
// cache) beside the limits of ISO 16505 / IEC 63033-3 and FMVSS 111 (daemon/compliance_limits.hpp).
//
// Input: each camera's video decoded as it plays (kDecode, replay figures), or decoded once at
// start into memory as YUYV or NV12 frames and converted to BGR per frame as a V4L2 camera's frames
// are (kRaw: what a live rig costs, without four H.264 decodes on the same cores). Raw frames are
// held in memory: peak memory then includes them.

#include <filesystem>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "capture/pixel_conversion.hpp"
#include "daemon/config/config.hpp"
#include "processing/colour/poisson_solver.hpp"
#include "processing/stitch/panorama_lut.hpp"
#include "render/view_camera.hpp"

namespace surroundd::bench {

enum class BenchInput { kDecode, kRaw };

// Where the surround view goes: an H.264 file, or a window on $DISPLAY given each picture read
// back (`window`, present: picture) or shown on the GPU (`egl-window`, present: egl).
enum class BenchOutput { kVideo, kWindow, kEglWindow };

struct PipelineBenchmarkOptions {
  std::vector<std::filesystem::path> recordings;
  BenchInput input = BenchInput::kDecode;
  capture::PixelLayout rawFormat = capture::PixelLayout::kYuyv;  // kRaw: kYuyv or kNv12
  int threads = 2;
  int repeats = 3;
  bool json = false;
  processing::PoissonSolverKind solver = processing::PoissonSolverKind::kAuto;
  processing::PanoramaProjection projection = processing::PanoramaProjection::kBowl;
  render::ViewKind view = render::ViewKind::kOrbit;
  cv::Size outputSize{1280, 720};
  daemon::ProcessingBackend backend = daemon::ProcessingBackend::kAuto;
  BenchOutput output = BenchOutput::kVideo;
};

int runPipelineBenchmark(const PipelineBenchmarkOptions& options);

}  // namespace surroundd::bench
