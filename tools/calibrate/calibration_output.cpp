#include "tools/calibrate/calibration_output.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <iterator>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "daemon/rig_yaml.hpp"
#include "tools/calibrate/calibrate_options.hpp"

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

// The file's leading comment block, verbatim: every line before the first that holds YAML.
std::string headerOf(const std::string& text) {
  std::size_t end = 0;
  while (end < text.size()) {
    const auto next = text.find('\n', end);
    const auto line = std::string_view(text).substr(
        end, next == std::string::npos ? std::string::npos : next - end);
    const auto first = line.find_first_not_of(" \t\r");
    if (first != std::string_view::npos && line[first] != '#') break;
    end = next == std::string::npos ? text.size() : next + 1;
  }
  std::string header = text.substr(0, end);
  if (!header.empty() && header.back() != '\n') header += '\n';
  return header;
}

// The rig document again, with `comment` beside `key` of each camera named in `cameras`. Only
// the paths down to those cameras are walked; every other node is emitted as it was read (its
// keys, their order and flow or block style).
std::string emitRig(const YAML::Node& document, std::span<const std::string> cameras,
                    const std::string& key, const std::string& comment) {
  const auto edited = [&](const YAML::Node& entry) {
    return entry.IsMap() && entry["name"] &&
           std::ranges::find(cameras, entry["name"].Scalar()) != cameras.end();
  };
  const auto styled = [](YAML::Emitter& out, const YAML::Node& node) {
    if (node.Style() == YAML::EmitterStyle::Flow) out << YAML::Flow;
  };
  YAML::Emitter out;
  styled(out, document);
  out << YAML::BeginMap;
  for (const auto& top : document) {
    out << YAML::Key << top.first << YAML::Value;
    if (top.first.Scalar() != "cameras" || !top.second.IsSequence()) {
      out << top.second;
      continue;
    }
    styled(out, top.second);
    out << YAML::BeginSeq;
    for (const auto& entry : top.second) {
      if (!edited(entry)) {
        out << entry;
        continue;
      }
      styled(out, entry);
      out << YAML::BeginMap;
      for (const auto& field : entry) {
        out << YAML::Key << field.first << YAML::Value;
        if (field.first.Scalar() == key) out << YAML::Comment(comment);
        out << field.second;
      }
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  out << YAML::EndMap;
  if (!out.good())
    throw std::runtime_error(fmt::format("cannot emit the rig: {}", out.GetLastError()));
  return std::string(out.c_str()) + "\n";
}

bool near(double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(1.0, std::abs(b)); }

// Equal within the digits written (12 significant; a pose also goes through its angles).
bool sameCalibration(const processing::CameraCalibration& a,
                     const processing::CameraCalibration& b) {
  const auto& i = a.intrinsics;
  const auto& j = b.intrinsics;
  bool same =
      a.name == b.name && a.role == b.role && i.model == j.model && i.imageSize == j.imageSize &&
      near(i.fx, j.fx) && near(i.fy, j.fy) && near(i.cx, j.cx) && near(i.cy, j.cy) &&
      // A pinhole's field is not written: it follows from the distortion.
      (i.model != processing::LensModel::kFisheye || near(i.maxFieldAngleRad, j.maxFieldAngleRad));
  const std::size_t coefficients = i.model == processing::LensModel::kFisheye ? 4 : 5;
  for (std::size_t k = 0; k < coefficients; ++k) {
    same = same && near(i.distortion[k], j.distortion[k]);
  }
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

// Replaces the `key` block (lens or mount) of each edited camera in a rig file, editing the YAML
// document itself so that every other key stays, and the file's header comment with it. All the
// edits go into one file written beside and renamed: the rig takes all of them or none. A result
// that does not read back to the changed calibrations is refused.
void updateRig(const std::filesystem::path& rig, const std::string& key,
               std::span<const RigEdit> edits, std::string_view comment) {
  const auto before = daemon::loadRigFile(rig);  // a rig that does not load is not edited
  auto expected = before;
  std::vector<std::string> cameras;
  cameras.reserve(edits.size());
  for (const auto& edit : edits) {
    const auto it = std::find_if(expected.begin(), expected.end(),
                                 [&](const auto& c) { return c.calibration.name == edit.camera; });
    if (it == expected.end()) rigCamera(rig, edit.camera);  // throws the message naming them
    edit.change(it->calibration);
    cameras.push_back(edit.camera);
  }

  std::ifstream in(rig);
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  YAML::Node document = YAML::Load(text);
  for (auto entry : document["cameras"]) {
    for (const auto& edit : edits) {
      if (entry.IsMap() && entry["name"] && entry["name"].Scalar() == edit.camera) {
        entry[key] = YAML::Load(block(key, "", edit.fields))[key];
      }
    }
  }
  // One line beside each block: yaml-cpp keeps no comment of the document, so this one is all the
  // record the rig has of where the values came from. The block is written in block style, so
  // that its values do not drop to the line below the comment as a flow map's would.
  std::string note(comment);
  std::ranges::replace(note, '\n', ' ');
  const std::string updated = headerOf(text) + emitRig(document, cameras, key, note);

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

}  // namespace surroundd::calibrate
