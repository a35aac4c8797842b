#include "tools/calibrate/calibration_output.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <iterator>
#include <span>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "common/regular_file.hpp"
#include "daemon/config/rig_yaml.hpp"
#include "tools/calibrate/calibrate_options.hpp"
#include "tools/calibrate/rig_text_edit.hpp"

namespace surroundd::calibrate {
namespace {

// `check`, when given, looks at the written file before it takes the name; what it throws leaves
// the old file as it was.
void writeAtomically(const std::filesystem::path& file, const std::string& text,
                     const std::function<void(const std::filesystem::path&)>& check = {}) {
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  const auto partial = std::filesystem::path(file.string() + ".part");
  {
    std::ofstream stream(partial, std::ios::trunc | std::ios::binary);
    stream << text;
    if (!stream.flush()) {
      stream.close();
      std::error_code ignored;
      std::filesystem::remove(partial, ignored);  // a full disk leaves no half file behind
      throw std::runtime_error(fmt::format("{}: cannot write the file", file.string()));
    }
  }
  if (check) {
    try {
      check(partial);
    } catch (...) {
      std::filesystem::remove(partial);
      throw;
    }
  }
  std::error_code renamed;
  std::filesystem::rename(partial, file, renamed);
  if (renamed) {
    std::error_code ignored;
    std::filesystem::remove(partial, ignored);
    throw std::runtime_error(
        fmt::format("{}: cannot replace the file ({})", file.string(), renamed.message()));
  }
}

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

template <typename Value>
void emitFields(YAML::Emitter& out, std::initializer_list<std::pair<const char*, Value>> fields) {
  for (const auto& [name, value] : fields) out << YAML::Key << name << YAML::Value << value;
}

// The rig reader's own writer, so that every lens model comes out as the rig schema reads it.
Fields lensFields(const processing::Intrinsics& lens) {
  return [&lens](YAML::Emitter& out) { daemon::emitLensFields(out, lens); };
}

Fields mountFields(const processing::Pose& pose) {
  return [&pose](YAML::Emitter& out) {
    const auto angles = processing::mountAnglesFromRotation(pose.rotation);
    emitFields<double>(out, {{"x_m", pose.position[0]},
                             {"y_m", pose.position[1]},
                             {"z_m", pose.position[2]},
                             {"yaw_deg", angles.yawDeg},
                             {"pitch_deg", angles.pitchDeg},
                             {"roll_deg", angles.rollDeg}});
  };
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

// Replaces the `key` block (lens or mount) of each edited camera in a rig file, in its text
// (rig_text_edit.hpp): every other byte stays. All the edits go into one file written beside and
// renamed: the rig takes all of them or none. A result that does not read back to the changed
// calibrations is refused.
void updateRig(const std::filesystem::path& rig, const std::string& key,
               std::span<const RigEdit> edits, std::string_view comment) {
  const auto before = daemon::loadRigFile(rig);  // a rig that does not load is not edited
  auto expected = before;
  std::vector<RigTextEdit> textEdits;
  textEdits.reserve(edits.size());
  for (const auto& edit : edits) {
    const auto it = std::find_if(expected.begin(), expected.end(),
                                 [&](const auto& c) { return c.calibration.name == edit.camera; });
    if (it == expected.end()) rigCamera(rig, edit.camera);  // throws the message naming them
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
    throw UsageError(fmt::format("--update-rig: {}: {} cannot be edited in place: {}", rig.string(),
                                 key, e.what()));
  }

  writeAtomically(rig, updated, [&](const std::filesystem::path& written) {
    const auto refuse = [&](const std::string& why) {
      throw std::runtime_error(
          fmt::format("{}: the updated rig would not read back to the new calibration ({}); the "
                      "rig is left as it was",
                      rig.string(), why));
    };
    std::vector<daemon::RigCamera> after;
    try {
      after = daemon::loadRigFile(written);
    } catch (const daemon::ConfigError& e) {
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

void writePng(const std::filesystem::path& file, const cv::Mat& picture) {
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", picture, bytes)) {
    throw std::runtime_error(fmt::format("{}: cannot encode the picture", file.string()));
  }
  writeAtomically(file, std::string(bytes.begin(), bytes.end()));
}

void writeLensBlock(const std::filesystem::path& file, const processing::Intrinsics& lens,
                    std::string_view comment) {
  writeAtomically(file, block("lens", comment, lensFields(lens)));
}

void writeMountBlock(const std::filesystem::path& file, const processing::Pose& pose,
                     std::string_view comment) {
  writeAtomically(file, block("mount", comment, mountFields(pose)));
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
  writeAtomically(file, std::string(out.c_str()) + "\n");
}

void updateRigLens(const std::filesystem::path& rig, const std::string& camera,
                   const processing::Intrinsics& lens, std::string_view comment) {
  checkRigPictureSize(rig, camera, lens.imageSize);
  const RigEdit edit{camera, lensFields(lens),
                     [&](processing::CameraCalibration& c) { c.intrinsics = lens; }};
  updateRig(rig, "lens", {&edit, 1}, comment);
}

void updateRigMount(const std::filesystem::path& rig, const std::string& camera,
                    const processing::Pose& pose, std::string_view comment) {
  const std::pair<std::string, processing::Pose> mount{camera, pose};
  updateRigMounts(rig, {&mount, 1}, comment);
}

void updateRigMounts(const std::filesystem::path& rig,
                     std::span<const std::pair<std::string, processing::Pose>> mounts,
                     std::string_view comment) {
  std::vector<RigEdit> edits;
  edits.reserve(mounts.size());
  for (const auto& mount : mounts) {
    const processing::Pose& pose = mount.second;
    edits.push_back({mount.first, mountFields(pose),
                     [&pose](processing::CameraCalibration& c) { c.pose = pose; }});
  }
  updateRig(rig, "mount", edits, comment);
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
