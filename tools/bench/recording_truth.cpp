#include "tools/bench/recording_truth.hpp"

#include <numbers>
#include <stdexcept>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "common/work_pool.hpp"
#include "daemon/config/rig_yaml.hpp"

namespace surroundd::bench {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180;

template <typename T>
T read(const YAML::Node& node, const char* key, const std::filesystem::path& file) {
  const YAML::Node value = node[key];
  if (!value) throw std::runtime_error(fmt::format("{}: missing key '{}'", file.string(), key));
  return value.as<T>();
}

}  // namespace

RecordingTruth loadRecordingTruth(const std::filesystem::path& folder) {
  RecordingTruth truth;
  truth.folder = folder;
  const daemon::RigFile rig = daemon::loadRig(folder / "rig.yaml");
  for (const auto& camera : rig.cameras) {
    truth.rig.cameras.push_back(camera.calibration);
    truth.videos.push_back(camera.replayedFile() ? camera.replayedFile()->path
                                                 : std::filesystem::path());
  }
  // The body the recording shows, masked as surroundd would mask it.
  if (rig.vehicle && rig.vehicle->bodyMasks) {
    WorkPool pool;
    for (auto& camera : truth.rig.cameras) {
      camera.bodyMask = processing::computeBodyMask(rig.vehicle->body(), camera, pool);
    }
  }
  const auto file = folder / "ground_truth.yaml";
  YAML::Node root;
  try {
    root = YAML::LoadFile(file.string());
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(fmt::format("{}: {}", file.string(), e.what()));
  }
  try {
    truth.seed = read<std::uint64_t>(root, "seed", file);
    truth.seconds = read<double>(root, "frames", file) / read<double>(root, "fps", file);
    const auto centre = read<std::vector<double>>(root, "virtual_centre_m", file);
    const YAML::Node panorama = root["panorama"];
    truth.panorama.size = {read<int>(panorama, "width_px", file),
                           read<int>(panorama, "height_px", file)};
    truth.panorama.elevationTopRad = read<double>(panorama, "elevation_top_deg", file) * kDegToRad;
    truth.panorama.elevationBottomRad =
        read<double>(panorama, "elevation_bottom_deg", file) * kDegToRad;
    truth.panorama.centre = {centre.at(0), centre.at(1), centre.at(2)};
    for (const auto& node : root["ground_truth_frames"]) {
      TruthFrame frame;
      frame.frame = read<int>(node, "frame", file);
      const YAML::Node pose = node["vehicle_pose"];
      frame.pose = {read<double>(pose, "x_m", file), read<double>(pose, "y_m", file),
                    read<double>(pose, "yaw_deg", file) * kDegToRad};
      frame.panorama = folder / read<std::string>(node, "panorama", file);
      for (const auto& camera : truth.rig.cameras) {
        frame.images.push_back(folder /
                               read<std::string>(node["cameras"][camera.name], "image", file));
      }
      truth.frames.push_back(std::move(frame));
    }
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(fmt::format("{}: {}", file.string(), e.what()));
  }
  if (truth.frames.empty()) {
    throw std::runtime_error(fmt::format("{}: no ground-truth frames", file.string()));
  }
  return truth;
}

}  // namespace surroundd::bench
