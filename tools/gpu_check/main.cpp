// surround-gpu-check: the GPU path (render/gpu_stitcher.hpp) from raw camera frames in memory to
// a picture read back, against the CPU path measured in the same run, on the kits that
// `surround-bench gpu-kit` writes (a panorama LUT and one raw YUYV frame set each).
//
//   surround-gpu-check [--frames N] [--view V] [--size WxH] KIT_FOLDER...
//
// Per kit and camera format (YUYV as carried, UYVY, NV12 and BGR converted from it at start-up):
// how far the GPU panorama is from the CPU Stitcher's (mean, 99th percentile, largest, in levels);
// milliseconds per frame set of the upload (and its GB/s), the stitch pass, the view's draw with
// its read-back, and the whole chain; and the CPU path's chain (Stitcher on every core, the
// panorama uploaded, the same draw). Stage times are wall clock around glFinish, so they hold on
// any driver, and the GPU's own time of each where GL_EXT_disjoint_timer_query is there. Each
// chain runs as the daemon's pipeline does: the next set's frames uploaded (GPU path) or stitched
// (CPU path) while the GPU draws and reads back the current picture, its only wait the read-back.
// For a view that does not move (top, 360, rear), also the alternative with no panorama at all
// (issue 20 point 3): the GPU stitch run on the view's own LUT (processing/stitch/view_lut.hpp,
// the table the CPU path gathers such views with), one pass at the picture's size sampling the
// cameras straight into the picture, timed the same way; and how far its picture is from the view
// drawn from the GPU panorama, where the view shows the panorama.
//
// Exit codes: 0 measured, 1 failed (named on stderr), 2 bad command line.

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string_view>
#include <thread>
#include <vector>

#include <GLES3/gl3.h>
#include <fmt/format.h>
#include <opencv2/core.hpp>

#include "common/build_info.hpp"
#include "common/masked_psnr.hpp"
#include "common/pixel_format.hpp"
#include "common/work_pool.hpp"
#include "processing/stitch/panorama_lut_cache.hpp"
#include "processing/stitch/stitcher.hpp"
#include "processing/stitch/view_lut.hpp"
#include "processing/surround_mesh.hpp"
#include "render/egl_context.hpp"
#include "render/gpu_stitcher.hpp"
#include "render/gpu_timer.hpp"
#include "render/surround_view.hpp"

namespace {

using namespace surroundd;
using Clock = std::chrono::steady_clock;

constexpr std::string_view kUsage =
    R"(usage: surround-gpu-check [--frames N] [--view V] [--size WxH] KIT_FOLDER...
  KIT_FOLDER  panorama.lut and camera<i>.yuyv, as surround-bench gpu-kit writes them
  --frames N  frame sets timed per measurement, median reported (default 300)
  --view V    top | 360 | orbit | split | rear (default orbit)
  --size WxH  the picture's size (default 1280x720)
)";

struct Options {
  int frames = 300;
  render::ViewKind view = render::ViewKind::kOrbit;
  cv::Size size{1280, 720};
  std::vector<std::filesystem::path> kits;
};

// The median of `frames` timings of `step`, in milliseconds.
template <typename Step>
double medianMs(int frames, Step&& step) {
  std::vector<double> ms;
  ms.reserve(static_cast<std::size_t>(frames));
  for (int i = 0; i < frames; ++i) {
    const auto start = Clock::now();
    step(i);
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
  }
  std::nth_element(ms.begin(), ms.begin() + static_cast<std::ptrdiff_t>(ms.size() / 2), ms.end());
  return ms[ms.size() / 2];
}

std::vector<cv::Mat> readFrames(const std::filesystem::path& kit,
                                const processing::PanoramaLut& lut) {
  std::vector<cv::Mat> frames;
  for (std::size_t camera = 0; camera < lut.cameraSizes.size(); ++camera) {
    const auto path = kit / fmt::format("camera{}.yuyv", camera);
    cv::Mat& frame = frames.emplace_back(lut.cameraSizes[camera], CV_8UC2);
    const auto bytes = static_cast<std::streamsize>(frame.total() * frame.elemSize());
    std::ifstream file(path, std::ios::binary);
    if (!file.read(reinterpret_cast<char*>(frame.data), bytes) || file.peek() != EOF) {
      throw std::runtime_error(fmt::format("{}: expected {} bytes of YUYV ({}x{})", path.string(),
                                           bytes, frame.cols, frame.rows));
    }
  }
  return frames;
}

// The median GPU milliseconds of `step` over `frames` runs, each waited for (render::GpuTimer,
// GL_EXT_disjoint_timer_query).
template <typename Step>
double medianGpuMs(render::GpuTimer& timer, render::GpuStep as, int frames, Step&& step) {
  std::vector<double> ms;
  for (int i = 0; i < frames; ++i) {
    {
      const render::GpuTimer::Scope timed(&timer, as);
      step(i);
    }
    glFinish();
    for (const auto& reading : timer.collect()) {
      ms.push_back(std::chrono::duration<double, std::milli>(reading.time).count());
    }
  }
  if (ms.empty()) return 0;
  std::nth_element(ms.begin(), ms.begin() + static_cast<std::ptrdiff_t>(ms.size() / 2), ms.end());
  return ms[ms.size() / 2];
}

struct Agreement {
  double mean = 0;
  int p99 = 0;
  int largest = 0;
};

Agreement compare(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat difference;
  cv::absdiff(a, b, difference);
  std::array<std::size_t, 256> histogram{};
  const cv::Mat levels = difference.reshape(1);
  for (auto it = levels.begin<std::uint8_t>(); it != levels.end<std::uint8_t>(); ++it) {
    ++histogram[*it];
  }
  Agreement agreement;
  agreement.mean = cv::mean(levels)[0];
  std::size_t seen = 0;
  bool p99Found = false;
  for (int level = 0; level < 256; ++level) {
    seen += histogram[level];
    if (!p99Found && static_cast<double>(seen) >= 0.99 * static_cast<double>(levels.total())) {
      agreement.p99 = level;
      p99Found = true;
    }
    if (histogram[level] > 0) agreement.largest = level;
  }
  return agreement;
}

// The view drawn with no panorama: its own LUT stitched straight into the picture.
struct ViewTable {
  processing::PanoramaLut lut;
  cv::Mat shown;  // where the view shows the panorama (the rest is the car and background)
};

void checkViewTable(const ViewTable& table, PixelFormat format, const std::vector<cv::Mat>& held,
                    const cv::Mat& drawn, WorkPool& pool, int frames) {
  render::GpuStitcher direct(table.lut, format, pool);
  cv::Mat picture;
  direct.upload(held);
  direct.stitch();
  direct.readPanorama(picture);
  const double stitchMs = medianMs(frames, [&](int) {
    direct.stitch();
    glFinish();
  });
  const double chainMs = medianMs(frames, [&](int) {
    direct.stitch();
    direct.upload(held);
    direct.readPanorama(picture);
  });
  fmt::print(
      "        no panorama (the view's LUT, {}x{}): stitch {:.3f} ms, chain {:.3f} ms = {:.1f} "
      "fps; vs the view drawn from the panorama {:.1f} dB\n",
      table.lut.size.width, table.lut.size.height, stitchMs, chainMs, 1000.0 / chainMs,
      maskedPsnr(picture, drawn, table.shown));
}

void checkKit(const std::filesystem::path& kit, const Options& options) {
  auto lookup = processing::PanoramaLutCache::loadFile(kit / "panorama.lut");
  if (!lookup.lut) {
    throw std::runtime_error(fmt::format("{}: {}", (kit / "panorama.lut").string(),
                                         lookup.problem == "absent" ? "absent" : lookup.problem));
  }
  const processing::PanoramaLut& lut = *lookup.lut;
  const std::vector<cv::Mat> yuyv = readFrames(kit, lut);
  WorkPool pool(static_cast<int>(std::max(1U, std::thread::hardware_concurrency())));
  processing::Stitcher stitcher(lut, pool);

  processing::PanoramaGeometry geometry;
  geometry.size = lut.size;
  render::SurroundScene scene(processing::buildSurroundMesh({}, geometry), geometry, {},
                              lut.cameraSizes.front());
  render::SurroundView view(scene, options.size, options.view, {});
  const int frames = options.frames;
  const auto drawAndCollect = [&](int i) {
    view.draw(i / 30.0);
    view.collect();
  };
  render::GpuTimer gpuTimer;
  std::optional<ViewTable> viewTable;
  if (!view.moves()) {
    const cv::Mat positions = view.panoramaPositions(0);
    viewTable = ViewTable{processing::composeViewLut(lut, positions, pool),
                          render::SurroundView::panoramaShown(positions)};
  }

  fmt::print("{}: {} cameras of {}x{}, panorama {}x{}, {} view {}x{}, {} frame sets a figure\n",
             kit.filename().string(), lut.cameraSizes.size(), lut.cameraSizes.front().width,
             lut.cameraSizes.front().height, lut.size.width, lut.size.height,
             render::toString(options.view), options.size.width, options.size.height, frames);

  // The CPU path, in the same run: stitch on every core, the panorama uploaded and drawn.
  cv::Mat cpuPanorama;
  scene.samplePanoramaFrom(0);
  const double cpuStitchMs =
      medianMs(frames, [&](int) { stitcher.stitch(yuyv, PixelFormat::kYuyv, cpuPanorama); });
  scene.uploadPanorama(cpuPanorama);
  const double cpuChainMs = medianMs(frames, [&](int i) {
    view.draw(i / 30.0);
    stitcher.stitch(yuyv, PixelFormat::kYuyv, cpuPanorama);
    view.collect();
    scene.uploadPanorama(cpuPanorama);
  });
  fmt::print("  CPU path (YUYV, {} threads): stitch {:.2f} ms, chain {:.2f} ms = {:.1f} fps\n",
             pool.threads(), cpuStitchMs, cpuChainMs, 1000.0 / cpuChainMs);

  fmt::print("  {:<5} {:>22} {:>18} {:>9} {:>13} {:>9} {:>9} {:>9}\n", "GPU", "vs CPU mean/p99/max",
             "upload ms (GB/s)", "stitch ms", "draw+read ms", "chain ms", "chain fps", "vs CPU");
  for (const PixelFormat format :
       {PixelFormat::kYuyv, PixelFormat::kUyvy, PixelFormat::kNv12, PixelFormat::kBgr}) {
    std::vector<cv::Mat> held(yuyv.size());
    std::size_t bytes = 0;
    for (std::size_t camera = 0; camera < yuyv.size(); ++camera) {
      cv::Mat bgr;
      heldToBgr(yuyv[camera], PixelFormat::kYuyv, bgr);
      bgrToHeld(bgr, format, held[camera]);
      bytes += held[camera].total() * held[camera].elemSize();
    }
    render::GpuStitcher gpu(lut, format, pool);
    cv::Mat reference;
    cv::Mat panorama;
    stitcher.stitch(held, format, reference);
    gpu.upload(held);
    gpu.stitch();
    gpu.readPanorama(panorama);
    const Agreement agreement = compare(panorama, reference);

    const double uploadMs = medianMs(frames, [&](int) {
      gpu.upload(held);
      glFinish();
    });
    const double stitchMs = medianMs(frames, [&](int) {
      gpu.stitch();
      glFinish();
    });
    scene.samplePanoramaFrom(gpu.panorama());
    const double drawMs = medianMs(frames, drawAndCollect);
    gpu.upload(held);
    const double chainMs = medianMs(frames, [&](int i) {
      gpu.stitch();
      view.draw(i / 30.0);
      gpu.upload(held);
      view.collect();
    });
    std::string gpuTimes = "no GL_EXT_disjoint_timer_query";
    if (gpuTimer.available()) {
      gpuTimes = fmt::format(
          "upload {:.3f} ms, stitch {:.3f} ms, draw+read {:.3f} ms",
          medianGpuMs(gpuTimer, render::GpuStep::kUpload, frames, [&](int) { gpu.upload(held); }),
          medianGpuMs(gpuTimer, render::GpuStep::kStitch, frames, [&](int) { gpu.stitch(); }),
          medianGpuMs(gpuTimer, render::GpuStep::kDraw, frames, drawAndCollect));
    }
    scene.samplePanoramaFrom(0);
    fmt::print(
        "  {:<5} {:>12.2f} / {:>2} / {:>3} {:>9.3f} ({:>5.1f}) {:>9.3f} {:>13.3f} {:>9.3f} "
        "{:>9.1f} {:>8.1f}x\n",
        toString(format), agreement.mean, agreement.p99, agreement.largest, uploadMs,
        static_cast<double>(bytes) / (uploadMs * 1e6), stitchMs, drawMs, chainMs, 1000.0 / chainMs,
        cpuChainMs / chainMs);
    fmt::print("        GPU time: {}\n", gpuTimes);
    if (viewTable) {
      gpu.upload(held);
      gpu.stitch();
      scene.samplePanoramaFrom(gpu.panorama());
      view.draw(0);
      const cv::Mat drawn = view.collect().clone();
      scene.samplePanoramaFrom(0);
      checkViewTable(*viewTable, format, held, drawn, pool, frames);
    }
  }
}

bool parseNumber(std::string_view text, int& value) {
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size();
}

int usageError(std::string_view message) {
  fmt::print(stderr, "surround-gpu-check: {}\n{}", message, kUsage);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    const std::string_view value = i + 1 < argc ? argv[i + 1] : "";
    if (arg == "--help" || arg == "-h") {
      fmt::print("{}", kUsage);
      return 0;
    }
    if (arg == "--version") {
      fmt::print("{}", surroundd::versionText("surround-gpu-check"));
      return 0;
    }
    if (arg == "--frames") {
      if (!parseNumber(value, options.frames) || options.frames < 1 || options.frames > 100000) {
        return usageError("--frames needs a number from 1 to 100000");
      }
      ++i;
    } else if (arg == "--view") {
      const auto view = render::parseViewKind(value);
      if (!view) return usageError("--view needs one of " + render::viewNameList(", "));
      options.view = *view;
      ++i;
    } else if (arg == "--size") {
      const auto x = value.find('x');
      int width = 0;
      int height = 0;
      if (x == std::string_view::npos || !parseNumber(value.substr(0, x), width) ||
          !parseNumber(value.substr(x + 1), height) || width < 2 || height < 2 || width % 2 != 0 ||
          height % 2 != 0) {
        return usageError("--size needs an even WIDTHxHEIGHT such as 1280x720");
      }
      options.size = {width, height};
      ++i;
    } else if (arg.starts_with("--")) {
      return usageError(fmt::format("unknown option '{}'", arg));
    } else {
      options.kits.emplace_back(arg);
    }
  }
  if (options.kits.empty()) return usageError("no kit folder given");
  try {
    const render::EglContext context;
    fmt::print("surround-gpu-check: EGL {}\n", context.description());
    for (const auto& kit : options.kits) checkKit(kit, options);
  } catch (const std::exception& e) {
    fmt::print(stderr, "surround-gpu-check: {}\n", e.what());
    return 1;
  }
  return 0;
}
