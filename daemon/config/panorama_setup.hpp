#pragma once
// The panorama the config asks for: its settings, and its LUT, taken from the on-disk cache when
// one was built for exactly these inputs, or built (progress in the log) and stored there.

#include <filesystem>

#include "daemon/config/config.hpp"
#include "processing/stitch/panorama_lut.hpp"
#include "processing/surround_mesh.hpp"

namespace surroundd {
class WorkPool;
}

namespace surroundd::daemon {

// The rig's calibration with each camera's body mask: computed from the vehicle (when the config
// has one and body_masks is on) and the camera's own body_mask. Throws std::runtime_error naming a
// mask picture that cannot be used.
processing::Rig rigOf(const Config& config, WorkPool& pool);

// The pixels of camera `index` that see the vehicle's body (CV_8U, 255 = body), or an empty Mat.
cv::Mat bodyMaskOf(const Config& config, std::size_t index, WorkPool& pool);

// The panorama is seen from (0, 0, mean camera height): the rig's virtual centre, where the
// generator's ground truth is rendered from too.
processing::PanoramaSettings panoramaSettings(const Config& config);

// The render mesh: mesh.*, with the bowl of the panorama's projection.
processing::MeshSettings meshSettings(const Config& config);

// panorama.cache_dir, or the default it documents.
std::filesystem::path lutCacheDir(const Config& config);

// Throws std::runtime_error naming the config for a rig that cannot make a panorama. A cache that
// cannot be written is logged and skipped.
processing::PanoramaLut obtainPanoramaLut(const Config& config, const processing::Rig& rig,
                                          WorkPool& pool);

}  // namespace surroundd::daemon
