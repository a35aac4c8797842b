#pragma once
// The recording's YAML side files: ground_truth.yaml (what the generator did: photometrics,
// timing, poses, panorama geometry) and manifest.yaml (cache key, arguments, durations).

#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include "tools/synth/recording_plan.hpp"

namespace surroundd::synth {

void writeGroundTruthYaml(const std::filesystem::path& file, const RecordingPlan& plan,
                          const std::vector<int>& framesWritten);

void writeManifest(const std::filesystem::path& file, const RecordingPlan& plan,
                   const std::map<std::string, double>& durationsS);

// The key of an existing manifest; nullopt when there is none or it cannot be read.
std::optional<std::string> readManifestKey(const std::filesystem::path& file);

// Ground-truth image names, relative to the recording folder.
std::string panoramaName(int frame);
std::string cameraImageName(const std::string& camera, int frame);
// The true body mask of a camera (recordings of a rig with a `vehicle:` only).
std::string bodyMaskName(const std::string& camera);
// A knocked camera's body mask from its turn on (--turn).
std::string turnedBodyMaskName(const std::string& camera);

}  // namespace surroundd::synth
