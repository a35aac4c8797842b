#pragma once
// The configs the pipeline tests run: a rig file, usually a generated recording's
// (tests/fixtures.cmake), replayed as fast as it decodes, with a small mosaic, writing `outputs`.

#include <filesystem>
#include <string_view>
#include <vector>

#include "daemon/config/config.hpp"
#include "daemon/config/rig_yaml.hpp"
#include "daemon/outputs/snapshot/snapshot_output.hpp"
#include "daemon/outputs/video/video_output.hpp"

namespace surroundd::daemon {

// `rig` replayed as fast as it decodes, with a small mosaic, writing `outputs`.
inline Config rigReplay(const std::filesystem::path& rig, std::vector<OutputConfig> outputs) {
  Config config;
  config.file = rig;
  config.cameras = loadRigFile(rig);
  config.capture.pacing = capture::Pacing::kAsFastAsPossible;
  config.render.widthPx = 320;
  config.render.heightPx = 180;
  config.outputs = std::move(outputs);
  return config;
}

inline Config fixtureReplay(std::string_view fixture, std::vector<OutputConfig> outputs) {
  return rigReplay(std::filesystem::path(SURROUNDD_FIXTURE_DIR) / fixture / "rig.yaml",
                   std::move(outputs));
}

// A quarter-size panorama (512x256) whose LUT is cached in `cacheDir`: enough for the tests that
// look at which camera shows where.
inline void useSmallPanorama(Config& config, const std::filesystem::path& cacheDir) {
  config.panorama.widthPx = 512;
  config.panorama.heightPx = 256;
  config.panorama.cacheDir = cacheDir;
}

// A snapshot of `stream` at `path`, `atSeconds` into the stream.
inline OutputConfig snapshotAt(const std::filesystem::path& path, OutputStream stream,
                               double atSeconds) {
  OutputConfig snapshot;
  snapshot.kind = OutputKind::kSnapshot;
  snapshot.stream = stream;
  snapshot.path = path;
  snapshot.settings = OutputSettings(SnapshotOutputSettings{atSeconds});
  return snapshot;
}

// One video output (a single file) at `path`.
inline OutputConfig videoOutputAt(const std::filesystem::path& path,
                                  VideoOutputSettings settings = {}) {
  OutputConfig video;
  video.path = path;
  video.settings = OutputSettings(std::move(settings));
  return video;
}

// H.264 at crf 0 on BGR: each picture as it was handed over, bit for bit.
inline VideoOutputSettings losslessBgr() {
  VideoOutputSettings video;
  video.h264.crf = 0;
  video.h264.pixelFormat = "bgr24";
  return video;
}

}  // namespace surroundd::daemon
