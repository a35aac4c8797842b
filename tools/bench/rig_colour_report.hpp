#pragma once
// surround-bench colour CONFIG.yaml: colour correction on any rig a surroundd config describes
// (the shared real rigs, a user's own car), from the first frame of each camera. Per seam: the
// ground misalignment and the colour step on near and far ground with no correction, global gains
// and Poisson (seam_measures.hpp); the panorama's mean level against uncorrected; what Poisson
// clamped or dropped. With an output folder, the panoramas as PNG.

#include <filesystem>

namespace surroundd::bench {

void reportRigColour(const std::filesystem::path& config, int threads,
                     const std::filesystem::path& pictures = {});

}  // namespace surroundd::bench
