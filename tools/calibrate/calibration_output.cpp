#include "tools/calibrate/calibration_output.hpp"

#include <algorithm>
#include <fstream>
#include <utility>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "daemon/rig_yaml.hpp"
#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {
namespace {

void writeAtomically(const std::filesystem::path& file, const std::string& text) {
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  const auto partial = std::filesystem::path(file.string() + ".part");
  {
    std::ofstream stream(partial, std::ios::trunc);
    stream << text;
    if (!stream.flush()) {
      throw std::runtime_error(fmt::format("{}: cannot write the file", partial.string()));
    }
  }
  std::filesystem::rename(partial, file);
}

// One block `key: {name: value, ...}` of the rig schema, with a comment on top.
std::string block(std::string_view key, std::string_view comment,
                  const std::function<void(YAML::Emitter&)>& fields) {
  YAML::Emitter out;
  out.SetDoublePrecision(12);  // far below any calibration's uncertainty, still readable
  if (!comment.empty()) out << YAML::Comment(std::string(comment));
  out << YAML::BeginMap << YAML::Key << std::string(key) << YAML::Value << YAML::BeginMap;
  fields(out);
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

template <typename Value>
void emitFields(YAML::Emitter& out, std::initializer_list<std::pair<const char*, Value>> fields) {
  for (const auto& [name, value] : fields) out << YAML::Key << name << YAML::Value << value;
}

// Reads a rig, lets `change` edit the named camera, writes the rig back.
template <typename Change>
void updateRig(const std::filesystem::path& rig, const std::string& camera, Change change,
               std::string_view comment) {
  auto cameras = daemon::loadRigFile(rig);
  const auto it = std::find_if(cameras.begin(), cameras.end(),
                               [&](const auto& c) { return c.calibration.name == camera; });
  if (it == cameras.end()) rigCamera(rig, camera);  // throws the message naming the cameras
  change(it->calibration);
  daemon::writeRigFile(rig, cameras, comment);
}

}  // namespace

void writeLensBlock(const std::filesystem::path& file, const processing::Intrinsics& lens,
                    std::string_view comment) {
  // The rig reader's own writer, so that every lens model comes out as the rig schema reads it.
  writeAtomically(
      file, block("lens", comment, [&](YAML::Emitter& out) { daemon::emitLensFields(out, lens); }));
}

void writeMountBlock(const std::filesystem::path& file, const processing::Pose& pose,
                     std::string_view comment) {
  const auto angles = processing::mountAnglesFromRotation(pose.rotation);
  writeAtomically(file, block("mount", comment, [&](YAML::Emitter& out) {
                    emitFields<double>(out, {{"x_m", pose.position[0]},
                                             {"y_m", pose.position[1]},
                                             {"z_m", pose.position[2]},
                                             {"yaw_deg", angles.yawDeg},
                                             {"pitch_deg", angles.pitchDeg},
                                             {"roll_deg", angles.rollDeg}});
                  }));
}

void updateRigLens(const std::filesystem::path& rig, const std::string& camera,
                   const processing::Intrinsics& lens, std::string_view comment) {
  updateRig(
      rig, camera, [&](processing::CameraCalibration& c) { c.intrinsics = lens; }, comment);
}

void updateRigMount(const std::filesystem::path& rig, const std::string& camera,
                    const processing::Pose& pose, std::string_view comment) {
  updateRig(
      rig, camera, [&](processing::CameraCalibration& c) { c.pose = pose; }, comment);
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

}  // namespace surroundd::calibrate
