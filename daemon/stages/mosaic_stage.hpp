#pragma once
// The mosaic: every camera's picture side by side, labelled, faulty ones marked (render/mosaic.hpp)
// — composed for each set while a working output shows it.

#include <optional>

#include <opencv2/core.hpp>

#include "daemon/config/config.hpp"
#include "daemon/pipeline_stage.hpp"
#include "render/mosaic.hpp"

namespace surroundd::daemon {

class MosaicStage final : public PipelineStage {
 public:
  explicit MosaicStage(const Config& config);

  void process(FrameWork& work, StageTimes& times) override;

  // The composed mosaic, reused for every set (black before the first).
  std::optional<StreamPicture> streamPicture(OutputStream stream) const override {
    if (stream != OutputStream::kMosaic) return std::nullopt;
    return StreamPicture{&canvas_, mosaic_.outputSize()};
  }

 private:
  render::Mosaic mosaic_;
  cv::Mat canvas_;
};

}  // namespace surroundd::daemon
