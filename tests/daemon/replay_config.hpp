#pragma once
// The config the pipeline tests run: a generated recording (tests/fixtures.cmake) replayed as fast
// as it decodes, with a small mosaic, writing `outputs`.

#include <filesystem>
#include <string_view>
#include <vector>

#include "daemon/config.hpp"
#include "daemon/rig_yaml.hpp"

namespace surroundd::daemon {

inline Config fixtureReplay(std::string_view fixture, std::vector<OutputConfig> outputs) {
  const auto rig = std::filesystem::path(SURROUNDD_FIXTURE_DIR) / fixture / "rig.yaml";
  Config config;
  config.file = rig;
  config.cameras = loadRigFile(rig);
  config.capture.pacing = capture::Pacing::kAsFastAsPossible;
  config.render.widthPx = 320;
  config.render.heightPx = 180;
  config.outputs = std::move(outputs);
  return config;
}

// One video output (a single file) at `path`.
inline OutputConfig videoOutputAt(const std::filesystem::path& path) {
  OutputConfig video;
  video.path = path;
  return video;
}

}  // namespace surroundd::daemon
