#include "daemon/config/rig_update.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "common/atomic_file.hpp"
#include "common/regular_file.hpp"
#include "daemon/config/rig_text_edit.hpp"
#include "daemon/config/rig_yaml.hpp"
#include "daemon/config/yaml_reader.hpp"

namespace surroundd::daemon {
namespace {

using Fields = std::function<void(YAML::Emitter&)>;

// A rig file is a few kilobytes; this bounds what a mistaken path could make it read.
constexpr std::size_t kMaxRigBytes = std::size_t{16} << 20;

// `fields` as one flow map, "{name: value, ...}".
std::string flowMap(const Fields& fields) {
  YAML::Emitter out;
  out.SetDoublePrecision(12);  // far below any calibration's uncertainty, still readable
  out << YAML::Flow << YAML::BeginMap;
  fields(out);
  out << YAML::EndMap;
  return out.c_str();
}

bool near(double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(1.0, std::abs(b)); }

bool near(std::span<const double> a, std::span<const double> b) {
  return std::ranges::equal(a, b, [](double x, double y) { return near(x, y); });
}

// Equal within the digits written (12 significant; a pose also goes through its angles).
bool sameCalibration(const processing::CameraCalibration& a,
                     const processing::CameraCalibration& b) {
  const auto& i = a.intrinsics;
  const auto& j = b.intrinsics;
  bool same =
      a.name == b.name && a.role == b.role && i.model == j.model && i.imageSize == j.imageSize &&
      near(i.fx, j.fx) && near(i.fy, j.fy) && near(i.cx, j.cx) && near(i.cy, j.cy) &&
      // A pinhole's field is not written: it follows from the distortion.
      (!processing::isWideAngle(i.model) || near(i.maxFieldAngleRad, j.maxFieldAngleRad)) &&
      near(i.distortion, j.distortion) && near(i.ocam.c, j.ocam.c) && near(i.ocam.d, j.ocam.d) &&
      near(i.ocam.e, j.ocam.e) && near(i.ocam.worldToImage, j.ocam.worldToImage) &&
      near(i.ocam.imageToWorld, j.ocam.imageToWorld);
  for (int k = 0; k < 3; ++k) same = same && near(a.pose.position[k], b.pose.position[k]);
  for (int k = 0; k < 9; ++k) same = same && near(a.pose.rotation.val[k], b.pose.rotation.val[k]);
  return same;
}

// One camera's new `key` block: its fields as written, and the change they make to its
// calibration (what the rig must read back to).
struct RigEdit {
  std::string camera;
  Fields fields;
  std::function<void(processing::CameraCalibration&)> change;
};

void updateRig(const std::filesystem::path& rig, const std::string& key,
               std::span<const RigEdit> edits, std::string_view comment) {
  const auto before = loadRigFile(rig);  // a rig that does not load is not edited
  auto expected = before;
  std::vector<RigTextEdit> textEdits;
  textEdits.reserve(edits.size());
  for (const auto& edit : edits) {
    const auto it = std::ranges::find_if(
        expected, [&](const auto& c) { return c.calibration.name == edit.camera; });
    if (it == expected.end()) {
      std::string names;
      for (const auto& camera : before) {
        names += (names.empty() ? "" : ", ") + camera.calibration.name;
      }
      throw std::invalid_argument(fmt::format("the rig '{}' has no camera '{}' (it has {})",
                                              rig.string(), edit.camera, names));
    }
    edit.change(it->calibration);
    textEdits.push_back({edit.camera, flowMap(edit.fields)});
  }
  // The comment is all the record the rig has of where the values came from: beside each value.
  std::string note(comment);
  std::ranges::replace(note, '\n', ' ');
  std::string updated;
  try {
    updated = editRigText(readRegularFile(rig, kMaxRigBytes), key, textEdits, note);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(
        fmt::format("{}: {} cannot be edited in place: {}", rig.string(), key, e.what()));
  }
  writeFileAtomically(rig, updated, [&](const std::filesystem::path& written) {
    const auto refuse = [&](const std::string& why) {
      throw std::runtime_error(
          fmt::format("{}: the updated rig would not read back to the new calibration ({}); the "
                      "rig is left as it was",
                      rig.string(), why));
    };
    std::vector<RigCamera> after;
    try {
      after = loadRigFile(written);
    } catch (const ConfigError& e) {
      refuse(e.what());
    }
    if (after.size() != expected.size()) refuse("the number of cameras changed");
    for (std::size_t c = 0; c < after.size(); ++c) {
      if (!sameCalibration(after[c].calibration, expected[c].calibration)) {
        refuse(fmt::format("camera '{}' differs", expected[c].calibration.name));
      }
    }
  });
}

}  // namespace

void updateRigLens(const std::filesystem::path& rig, const std::string& camera,
                   const processing::Intrinsics& lens, std::string_view comment) {
  const RigEdit edit{camera, [&lens](YAML::Emitter& out) { emitLensFields(out, lens); },
                     [&](processing::CameraCalibration& c) { c.intrinsics = lens; }};
  updateRig(rig, "lens", {&edit, 1}, comment);
}

void updateRigMounts(const std::filesystem::path& rig,
                     std::span<const std::pair<std::string, processing::Pose>> mounts,
                     std::string_view comment) {
  std::vector<RigEdit> edits;
  edits.reserve(mounts.size());
  for (const auto& mount : mounts) {
    const processing::Pose& pose = mount.second;
    edits.push_back({mount.first, [&pose](YAML::Emitter& out) { emitMountFields(out, pose); },
                     [&pose](processing::CameraCalibration& c) { c.pose = pose; }});
  }
  updateRig(rig, "mount", edits, comment);
}

}  // namespace surroundd::daemon
