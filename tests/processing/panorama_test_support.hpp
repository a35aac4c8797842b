#pragma once
// The tests' panorama set-up: the synth_small recording (paper rig, 4 x 320x180, with ground
// truth at 512x256) and its noise-free camera images.

#include <filesystem>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "processing/stitch/panorama_lut.hpp"
#include "tools/bench/recording_truth.hpp"

namespace surroundd::processing::testing {

inline const bench::RecordingTruth& smallRecording() {
  static const bench::RecordingTruth truth =
      bench::loadRecordingTruth(std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_small");
  return truth;
}

inline PanoramaSettings settingsFor(const bench::RecordingTruth& truth,
                                    PanoramaProjection projection = PanoramaProjection::kBowl) {
  PanoramaSettings settings;
  settings.geometry = truth.panorama;
  settings.projection = projection;
  return settings;
}

inline std::vector<cv::Mat> truthImages(const bench::TruthFrame& frame) {
  std::vector<cv::Mat> images;
  for (const auto& path : frame.images) images.push_back(cv::imread(path.string()));
  return images;
}

}  // namespace surroundd::processing::testing
