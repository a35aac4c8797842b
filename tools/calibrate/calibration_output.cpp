#include "tools/calibrate/calibration_output.hpp"

#include <functional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "common/atomic_file.hpp"
#include "daemon/config/rig_update.hpp"
#include "daemon/config/rig_yaml.hpp"
#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {
namespace {

using Fields = std::function<void(YAML::Emitter&)>;

// One block `key: {name: value, ...}` of the rig schema, with a comment on top.
std::string block(std::string_view key, std::string_view comment, const Fields& fields) {
  YAML::Emitter out;
  out.SetDoublePrecision(12);  // far below any calibration's uncertainty, still readable
  if (!comment.empty()) out << YAML::Comment(std::string(comment));
  out << YAML::BeginMap << YAML::Key << std::string(key) << YAML::Value << YAML::BeginMap;
  fields(out);
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

// The rig reader's own writer, so that every lens model comes out as the rig schema reads it.
Fields lensFields(const processing::Intrinsics& lens) {
  return [&lens](YAML::Emitter& out) { daemon::emitLensFields(out, lens); };
}

Fields mountFields(const processing::Pose& pose) {
  return [&pose](YAML::Emitter& out) { daemon::emitMountFields(out, pose); };
}

// The rig file's own update, its mistakes told as this tool's option's.
template <typename Update>
void updatingRig(Update&& update) {
  try {
    update();
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("--update-rig: {}", e.what()));
  }
}

}  // namespace

void writePng(const std::filesystem::path& file, const cv::Mat& picture) {
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", picture, bytes)) {
    throw std::runtime_error(fmt::format("{}: cannot encode the picture", file.string()));
  }
  writeFileAtomically(file, std::string(bytes.begin(), bytes.end()));
}

void writeLensBlock(const std::filesystem::path& file, const processing::Intrinsics& lens,
                    std::string_view comment) {
  writeFileAtomically(file, block("lens", comment, lensFields(lens)));
}

void writeMountBlock(const std::filesystem::path& file, const processing::Pose& pose,
                     std::string_view comment) {
  writeFileAtomically(file, block("mount", comment, mountFields(pose)));
}

void writeMountBlocks(const std::filesystem::path& file,
                      std::span<const std::pair<std::string, processing::Pose>> mounts,
                      std::string_view comment) {
  YAML::Emitter out;
  out.SetDoublePrecision(12);
  if (!comment.empty()) out << YAML::Comment(std::string(comment));
  out << YAML::BeginMap << YAML::Key << "cameras" << YAML::Value << YAML::BeginSeq;
  for (const auto& [name, pose] : mounts) {
    out << YAML::BeginMap << YAML::Key << "name" << YAML::Value << name << YAML::Key << "mount"
        << YAML::Value << YAML::Flow << YAML::BeginMap;
    mountFields(pose)(out);
    out << YAML::EndMap << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  writeFileAtomically(file, std::string(out.c_str()) + "\n");
}

void updateRigLens(const std::filesystem::path& rig, const std::string& camera,
                   const processing::Intrinsics& lens, std::string_view comment) {
  checkRigPictureSize(rig, camera, lens.imageSize);
  updatingRig([&] { daemon::updateRigLens(rig, camera, lens, comment); });
}

void updateRigMount(const std::filesystem::path& rig, const std::string& camera,
                    const processing::Pose& pose, std::string_view comment) {
  const std::pair<std::string, processing::Pose> mount{camera, pose};
  updateRigMounts(rig, {&mount, 1}, comment);
}

void updateRigMounts(const std::filesystem::path& rig,
                     std::span<const std::pair<std::string, processing::Pose>> mounts,
                     std::string_view comment) {
  updatingRig([&] { daemon::updateRigMounts(rig, mounts, comment); });
}

processing::CameraCalibration rigCamera(const std::filesystem::path& rig,
                                        const std::string& camera) {
  std::string names;
  for (const auto& entry : daemon::loadRigFile(rig)) {
    if (entry.calibration.name == camera) return entry.calibration;
    names += (names.empty() ? "" : ", ") + entry.calibration.name;
  }
  throw UsageError(fmt::format("--camera: the rig '{}' has no camera '{}' (it has {})",
                               rig.string(), camera, names));
}

void checkRigPictureSize(const std::filesystem::path& rig, const std::string& camera,
                         cv::Size pictures) {
  const cv::Size size = rigCamera(rig, camera).intrinsics.imageSize;
  if (size != pictures) {
    throw UsageError(fmt::format(
        "--update-rig: camera '{}' in {} takes {}x{} pictures, these are {}x{}: a lens fitted to "
        "them does not fit it; calibrate from that camera's own pictures, at its size",
        camera, rig.string(), size.width, size.height, pictures.width, pictures.height));
  }
}

}  // namespace surroundd::calibrate
