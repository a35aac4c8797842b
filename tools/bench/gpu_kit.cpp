#include "tools/bench/gpu_kit.hpp"

#include <fstream>
#include <stdexcept>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "common/pixel_format.hpp"
#include "processing/stitch/panorama_lut_cache.hpp"
#include "tools/bench/recording_truth.hpp"

namespace surroundd::bench {

void writeGpuKit(const std::filesystem::path& recording, const std::filesystem::path& kit,
                 WorkPool& pool) {
  const RecordingTruth truth = loadRecordingTruth(recording);
  processing::PanoramaSettings settings;
  settings.geometry = truth.panorama;
  const auto folder = kit / recording.filename();
  // The cache's own writer: written whole under a temporary name, then renamed.
  const processing::PanoramaLutCache cache(folder);
  const std::string key = processing::panoramaLutKey(truth.rig, settings);
  cache.store(key, processing::buildPanoramaLut(truth.rig, settings, pool));
  std::filesystem::rename(cache.fileFor(key), folder / "panorama.lut");

  const auto& images = truth.frames.front().images;
  for (std::size_t camera = 0; camera < images.size(); ++camera) {
    const cv::Mat bgr = cv::imread(images[camera].string(), cv::IMREAD_COLOR);
    if (bgr.empty())
      throw std::runtime_error(fmt::format("cannot read {}", images[camera].string()));
    cv::Mat yuyv;
    bgrToHeld(bgr, PixelFormat::kYuyv, yuyv);
    const auto path = folder / fmt::format("camera{}.yuyv", camera);
    std::ofstream file(path, std::ios::binary | std::ios::trunc);
    file.write(reinterpret_cast<const char*>(yuyv.data),
               static_cast<std::streamsize>(yuyv.total() * yuyv.elemSize()));
    if (!file.flush()) throw std::runtime_error(fmt::format("cannot write {}", path.string()));
  }
  fmt::print("gpu-kit: {} ({} cameras of {}x{}, panorama {}x{})\n", folder.string(), images.size(),
             truth.rig.cameras.front().intrinsics.imageSize.width,
             truth.rig.cameras.front().intrinsics.imageSize.height, settings.geometry.size.width,
             settings.geometry.size.height);
}

}  // namespace surroundd::bench
