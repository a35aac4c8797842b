#pragma once
// surround-bench colour CONFIG.yaml: colour correction on any rig a surroundd config describes
// (the shared real rigs, a user's own car), from the first frame of each camera. Per seam: the
// ground misalignment and the colour step on near and far ground with no correction, global gains
// and Poisson (seam_measures.hpp); the panorama's mean level against uncorrected; what Poisson
// clamped or dropped. With an output folder, the panoramas as PNG.

#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/colour/poisson_correction.hpp"

namespace surroundd {
class WorkPool;
}

namespace surroundd::bench {

// One rig's cameras (body masks included) and first frames, and how to correct them.
struct RigColourInput {
  std::string name;
  processing::Rig rig;
  processing::PanoramaSettings panorama;
  processing::ColourCorrectionSettings colour;
  std::vector<cv::Mat> frames;
};

// From a surroundd config whose cameras are files.
RigColourInput rigColourInput(const std::filesystem::path& config, WorkPool& pool);

void reportRigColour(const RigColourInput& input, WorkPool& pool,
                     const std::filesystem::path& pictures = {});

}  // namespace surroundd::bench
