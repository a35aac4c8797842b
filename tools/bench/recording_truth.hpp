#pragma once
// A surround-synth recording read back with its ground truth: the exact rig, the scene seed, and
// for the ground-truth frames the vehicle pose, the noise-free camera images and the true panorama
// seen from the virtual centre. For measuring the stitcher and colour correction against truth.

#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/panorama_geometry.hpp"
#include "processing/rig.hpp"
#include "tools/synth/vehicle_path.hpp"

namespace surroundd::bench {

struct TruthFrame {
  int frame = 0;
  synth::VehiclePose pose;
  std::filesystem::path panorama;             // true panorama, 8-bit BGR PNG
  std::vector<std::filesystem::path> images;  // noise-free camera images, in rig order
};

struct RecordingTruth {
  std::filesystem::path folder;
  processing::Rig rig;
  std::vector<std::filesystem::path> videos;  // in rig order
  std::uint64_t seed = 0;
  double seconds = 0;                     // the recording's length, which places the scene's yard
  processing::PanoramaGeometry panorama;  // of the true panoramas
  std::vector<TruthFrame> frames;
};

// Throws std::runtime_error naming the file and key when the folder is not a recording.
RecordingTruth loadRecordingTruth(const std::filesystem::path& folder);

}  // namespace surroundd::bench
