#include "daemon/stages/gpu_panorama.hpp"

#include <algorithm>
#include <span>
#include <string_view>
#include <utility>

#include <spdlog/spdlog.h>

#include "render/dmabuf_import.hpp"
#include "render/render_error.hpp"

namespace surroundd::daemon {
namespace {

// Whether processing.backend comes to the GPU on this renderer, and why.
std::pair<bool, std::string_view> gpuBackendOf(const Config& config, const render::EglContext& gl) {
  const ProcessingBackend backend = config.processing.backend;
  if (backend == ProcessingBackend::kCpu) return {false, "processing.backend: cpu"};
  if (backend == ProcessingBackend::kAuto && gl.software()) {
    return {false, "auto: the renderer runs on the CPU, where the CPU path is faster"};
  }
  if (config.colour.method == ColourMethod::kGain) {
    return {false, "gain compensation is applied on the CPU only"};
  }
  if (backend == ProcessingBackend::kAuto) return {true, "auto: a hardware renderer"};
  return {true, gl.software() ? "processing.backend: gpu, on a renderer that runs on the CPU "
                                "(slower than the CPU path)"
                              : "processing.backend: gpu"};
}

std::unique_ptr<render::GpuStitcher> stitcherFor(const PanoramaStage& panorama,
                                                 PixelFormat format) {
  auto stitcher = std::make_unique<render::GpuStitcher>(panorama.lut(), format, panorama.pool());
  stitcher->correctWith(panorama.colourField());
  return stitcher;
}

}  // namespace

GpuPanorama::GpuPanorama(const Config& config, const render::EglContext& gl,
                         PanoramaStage& panorama, PixelFormat cameraFormat)
    : panorama_(panorama), generation_(panorama.generation()) {
  auto [gpu, why] = gpuBackendOf(config, gl);
  if (gpu) {
    try {
      stitcher_ = stitcherFor(panorama, cameraFormat);
    } catch (const render::RenderError& e) {
      spdlog::warn("processing: the GPU cannot stitch the panorama: {}", e.what());
      why = "the GPU stitch could not be set up";
    }
  }
  importSaid_.resize(panorama.lut().cameraSizes.size());
  importRefusal_ =
      stitcher_ ? render::DmabufImport(cameraFormat, panorama.lut().cameraSizes.at(0)).refusal()
                : "the panorama is stitched on the CPU";
  spdlog::info("processing: {} ({}){}", stitcher_ ? "gpu" : "cpu", why,
               stitcher_ ? fmt::format(", frames uploaded as {}", toString(cameraFormat)) : "");
}

bool GpuPanorama::stitches(const FrameWork& work) const {
  if (!stitcher_) return false;
  const auto faults = std::span(work.faults).first(work.set.cameraCount);
  return std::ranges::none_of(faults, [](const char* fault) { return fault != nullptr; });
}

GLuint GpuPanorama::stitch(render::GpuTimer& timer) {
  const PixelFormat format = panorama_.frameFormat();
  if (stitcher_->format() != format) {
    spdlog::info("processing: the frames come in {}, not {}: the GPU stitch is set up for them",
                 toString(format), toString(stitcher_->format()));
    stitcher_ = stitcherFor(panorama_, format);
  } else if (generation_ != panorama_.generation()) {
    stitcher_ = stitcherFor(panorama_, format);
  }
  generation_ = panorama_.generation();
  {
    const render::GpuTimer::Scope timed(&timer, render::GpuStep::kUpload);
    stitcher_->upload(panorama_.frames(), panorama_.dmabufs());
  }
  sayHowFramesReachTheGpu();
  const render::GpuTimer::Scope timed(&timer, render::GpuStep::kStitch);
  stitcher_->stitch();
  return stitcher_->panorama();
}

void GpuPanorama::sayHowFramesReachTheGpu() {
  const auto& dmabufs = panorama_.dmabufs();
  for (std::size_t c = 0; c < dmabufs.size(); ++c) {
    if (dmabufs[c].planes == 0) continue;
    const char way = stitcher_->imported(c) ? 1 : 2;
    if (importSaid_[c] == way) continue;
    importSaid_[c] = way;
    const std::string& name = panorama_.rig().cameras[c].name;
    if (way == 1) {
      spdlog::info("processing: camera '{}': frames taken from their DMABUFs, with no copy", name);
    } else {
      spdlog::warn("processing: camera '{}': frames uploaded through pixel buffers: {}", name,
                   stitcher_->importRefusal(c));
    }
  }
}

}  // namespace surroundd::daemon
