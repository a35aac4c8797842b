#include "tools/calibrate/import/pjlab_layout.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "daemon/config/yaml_reader.hpp"
#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {
namespace {

std::vector<double> numbers(const YAML::Node& node, std::size_t count, const std::string& where) {
  std::vector<double> values;
  try {
    if (node.IsSequence()) {
      for (const auto& item : node) {
        if (item.IsSequence()) {
          for (const auto& inner : item) values.push_back(inner.as<double>());
        } else {
          values.push_back(item.as<double>());
        }
      }
    }
  } catch (const YAML::Exception&) {
    values.clear();
  }
  if (values.size() != count) {
    throw UsageError(fmt::format("{}: expected a list of {} numbers{}", where, count,
                                 node ? "" : " (the key is missing)"));
  }
  if (!std::ranges::all_of(values, [](double v) { return std::isfinite(v); })) {
    throw UsageError(
        fmt::format("{}: expected {} finite numbers (no NaN or infinity)", where, count));
  }
  return values;
}

}  // namespace

std::vector<std::pair<std::string, std::vector<std::filesystem::path>>> pjlabCameraFiles(
    const std::filesystem::path& dir) {
  const auto intrinsic = dir / "intrinsic";
  std::error_code ec;
  if (!std::filesystem::is_directory(intrinsic, ec)) {
    throw UsageError(
        fmt::format("--pjlab: {} has no folder 'intrinsic' (expected intrinsic/<Cam>.json and "
                    "extrinsic/<Cam>.json)",
                    dir.string()));
  }
  std::vector<std::pair<std::string, std::vector<std::filesystem::path>>> cameras;
  for (const auto& entry : std::filesystem::directory_iterator(intrinsic)) {
    if (entry.path().extension() != ".json") continue;
    const auto name = entry.path().stem().string();
    const auto extrinsic = dir / "extrinsic" / entry.path().filename();
    if (!std::filesystem::is_regular_file(extrinsic, ec)) {
      throw UsageError(fmt::format("--pjlab: {} has no extrinsic file {}", entry.path().string(),
                                   extrinsic.string()));
    }
    cameras.push_back({name, {entry.path(), extrinsic}});
  }
  if (cameras.empty()) {
    throw UsageError(fmt::format("--pjlab: no <Cam>.json in {}", intrinsic.string()));
  }
  std::ranges::sort(cameras);
  return cameras;
}

std::vector<NamedCalibration> readPjlabYaml(const std::filesystem::path& file,
                                            PoseDirection direction) {
  YAML::Node root;
  try {
    root = daemon::parseYamlFile(file);
  } catch (const daemon::ConfigError& error) {
    throw UsageError(error.messages().front());
  }
  // Each node's kind is checked before it is indexed: yaml-cpp throws its own error (found by
  // import_fuzz: a document that is a scalar ended the program).
  if (!root.IsMap()) {
    throw UsageError(fmt::format("{}: expected a map of image_size and cameras", file.string()));
  }
  const auto size = numbers(root["image_size"], 2, file.string() + ": image_size");
  const cv::Size imageSize = imageSizeFrom(size[0], size[1], file.string() + ": image_size");
  if (!root["cameras"].IsMap() || root["cameras"].size() == 0) {
    throw UsageError(
        fmt::format("{}: cameras: expected a map of camera names to K, D and "
                    "T_cam_from_G",
                    file.string()));
  }
  std::vector<NamedCalibration> cameras;
  for (const auto& entry : root["cameras"]) {
    NamedCalibration camera;
    if (!entry.first.IsScalar() || !entry.second.IsMap()) {
      throw UsageError(
          fmt::format("{}: cameras: expected each camera's name, then a map of K, D "
                      "and T_cam_from_G",
                      file.string()));
    }
    camera.sourceName = entry.first.Scalar();
    const auto& node = entry.second;
    const auto where = fmt::format("{}: cameras.{}.", file.string(), camera.sourceName);
    auto& c = camera.calibration;
    c.files.push_back(file);
    const auto k = numbers(node["K"], 4, where + "K");
    c.cameraMatrix = Found<cv::Mat>{cv::Mat(k, true).reshape(1, 1), where + "K"};
    const auto d = numbers(node["D"], 4, where + "D");
    c.distortion = Found<std::vector<double>>{d, where + "D"};
    c.imageSize = Found<cv::Size>{imageSize, file.string() + ": image_size"};
    const auto t = numbers(node["T_cam_from_G"], 16, where + "T_cam_from_G");
    const cv::Matx33d rotation(t[0], t[1], t[2], t[4], t[5], t[6], t[8], t[9], t[10]);
    c.pose = Found<CameraFromSource>{cameraFromSource(rotation, {t[3], t[7], t[11]}, direction),
                                     where + "T_cam_from_G"};
    cameras.push_back(std::move(camera));
  }
  return cameras;
}

}  // namespace surroundd::calibrate
