#pragma once
// What a stage's test hands it: synth_seams' rig under a config of the test's, and its cameras'
// first frames as one frame set, in pooled frames as camera streams hand them over.

#include <array>
#include <filesystem>
#include <optional>
#include <string>

#include "capture/frame.hpp"
#include "capture/frame_set.hpp"
#include "daemon/config/config.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::testing {

inline const std::filesystem::path kSeams =
    std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_seams";
inline const std::array<std::string, 4> kSeamsCameras{"front", "right", "back", "left"};

// synth_seams' rig with its recordings where the config finds them, the front camera's yaw
// `frontYaw` (degrees); `config` is the rest of the config, which names the rig as rig.yaml.
inline daemon::Config seamsConfig(const TempDir& dir, const std::string& frontYaw,
                                  const std::string& config) {
  std::string rig = fileBytes(kSeams / "rig.yaml");
  for (const std::string& name : kSeamsCameras) {
    const std::string source = "file: " + name + ".mkv";
    rig.replace(rig.find(source), source.size(), "file: " + (kSeams / (name + ".mkv")).string());
  }
  const std::string yaw = "yaw_deg: 0,";  // the front camera's, the first
  rig.replace(rig.find(yaw), yaw.size(), "yaw_deg: " + frontYaw + ",");
  dir.write("rig.yaml", rig);
  return daemon::loadConfig(dir.write("config.yaml", config));
}

// Each camera's first frame.
class SeamsFirstFrames {
 public:
  SeamsFirstFrames() {
    for (std::size_t c = 0; c < kSeamsCameras.size(); ++c) {
      const cv::Mat picture =
          decodeAll(kSeams / (kSeamsCameras[c] + ".mkv"), false, 1).images.at(0);
      pools_[c].emplace(1, picture.size());
      set.frames[c] = pools_[c]->tryAcquire();
      picture.copyTo(set.frames[c]->image);
    }
    set.cameraCount = kSeamsCameras.size();
  }
  capture::FrameSet set;

 private:
  std::array<std::optional<capture::FramePool>, kMaxCameras> pools_;
};

}  // namespace surroundd::testing
