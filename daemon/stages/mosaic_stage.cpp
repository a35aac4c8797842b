#include "daemon/stages/mosaic_stage.hpp"

#include <array>
#include <span>

#include "daemon/pipeline_ends.hpp"

namespace surroundd::daemon {

MosaicStage::MosaicStage(const Config& config)
    : mosaic_(cv::Size(config.render.widthPx, config.render.heightPx), cameraNames(config)),
      canvas_(mosaic_.outputSize(), CV_8UC3, cv::Scalar::all(0)) {}

void MosaicStage::process(FrameWork& work, StageTimes& times) {
  // Every set's mosaic, even when no output wants this frame: it may be the last one, which a
  // snapshot asked for after the end is given.
  if (!work.outputs.shows(OutputStream::kMosaic)) return;
  const std::size_t cameras = work.set.cameraCount;
  std::array<const cv::Mat*, kMaxCameras> images{};
  for (std::size_t c = 0; c < cameras; ++c) images[c] = work.bgr(c);
  mosaic_.compose(std::span(images.data(), cameras), canvas_,
                  std::span(work.faults.data(), cameras));
  times.lap(Stage::kMosaic);
}

}  // namespace surroundd::daemon
