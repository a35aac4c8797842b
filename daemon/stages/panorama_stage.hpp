#pragma once
// The panorama: every set's camera frames gathered through the panorama LUT (processing/
// stitcher.hpp), colour-corrected (Poisson or gain compensation, as colour_correction says) and
// each faulty camera's part marked. Made for every set, shown or not: colour correction follows
// the pictures over time.

#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "common/work_pool.hpp"
#include "daemon/config.hpp"
#include "daemon/pipeline_stage.hpp"
#include "processing/colour/gain_compensation.hpp"
#include "processing/colour/poisson_correction.hpp"
#include "processing/stitch/panorama_lut.hpp"
#include "processing/stitch/panorama_ownership.hpp"
#include "processing/stitch/stitcher.hpp"

namespace surroundd::daemon {

class PanoramaStage final : public PipelineStage {
 public:
  // Builds the LUT (or reads it from the cache) and the colour correction on `pool`, which must
  // outlive the stage. Throws std::runtime_error naming the config for a rig that cannot make a
  // panorama.
  PanoramaStage(const Config& config, WorkPool& pool);

  void process(FrameWork& work, StageTimes& times) override;

  // The corrected panorama of the last set, reused for every set; of lut().size.
  const cv::Mat& picture() const { return panorama_; }
  const processing::PanoramaLut& lut() const { return lut_; }

 private:
  PanoramaStage(const Config& config, WorkPool& pool, const processing::Rig& rig);
  void setUpColourCorrection(const Config& config, const processing::Rig& rig, WorkPool& pool);

  processing::PanoramaLut lut_;
  processing::Stitcher stitcher_;  // borrows lut_
  processing::PanoramaOwnership ownership_;
  std::unique_ptr<processing::PoissonColourCorrection> poisson_;  // colour_correction: poisson
  std::unique_ptr<processing::GainCompensation> gains_;           // colour_correction: gain
  std::vector<cv::Mat> corrected_;  // this set's frames (headers) that colour correction sees
  std::vector<cv::Mat> stitched_;   // this set's frames (headers), black for missing cameras
  std::vector<cv::Mat> blackFrames_;
  cv::Mat panorama_;
};

}  // namespace surroundd::daemon
