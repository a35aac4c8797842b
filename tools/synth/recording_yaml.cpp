#include "tools/synth/recording_yaml.hpp"

#include <cmath>
#include <fstream>
#include <numbers>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "tools/synth/ego_body.hpp"
#include "tools/synth/vehicle_path.hpp"

namespace surroundd::synth {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

void writeText(const std::filesystem::path& file, const YAML::Emitter& out) {
  if (!out.good()) {
    throw std::runtime_error(
        fmt::format("{}: cannot write YAML: {}", file.string(), out.GetLastError()));
  }
  std::ofstream stream(file, std::ios::trunc);
  stream << out.c_str() << '\n';
  if (!stream.flush()) throw std::runtime_error(fmt::format("{}: cannot write", file.string()));
}

}  // namespace

std::string panoramaName(int frame) { return fmt::format("ground_truth/panorama_{}.png", frame); }
std::string cameraImageName(const std::string& camera, int frame) {
  return fmt::format("ground_truth/{}_{}.png", camera, frame);
}
std::string bodyMaskName(const std::string& camera) {
  return fmt::format("ground_truth/body_mask_{}.png", camera);
}
std::string turnedBodyMaskName(const std::string& camera) {
  return fmt::format("ground_truth/body_mask_{}_turned.png", camera);
}

void writeGroundTruthYaml(const std::filesystem::path& file, const RecordingPlan& plan,
                          const std::vector<int>& framesWritten) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::Comment(
      "Ground truth of a surround-synth recording. Per camera pixel value (8-bit, per channel c):\n"
      "  x = L_c * gain * white_balance_bgr[c] * exposure(t) * vignette\n"
      "  value = clamp(round(255 * (min(x, 511.9) / 255)^gamma + N(0, noise_sigma^2)), 0, 255)\n"
      "  exposure(t) = 1 + drift_amplitude * sin(2 pi t / drift_period_s + drift_phase_rad),\n"
      "  t = frame / fps (nominal); vignette = 1 - vignetting * (1 - cos^4(theta')), theta' the\n"
      "  ray's angle off the optical axis (halved for fisheye lenses). L is the scene radiance\n"
      "  that the noise-free images ground_truth/<camera>_<frame>.png show (rounded).\n"
      "Images show the scene at the nominal frame time; timestamps add the camera's start\n"
      "offset and a per-frame jitter (at 1.5 m/s, 4 ms is 6 mm of motion).");
  out << YAML::BeginMap;
  out << YAML::Key << "generator_version" << YAML::Value << std::string(kGeneratorVersion);
  out << YAML::Key << "seed" << YAML::Value << plan.options.seed;
  out << YAML::Key << "fps" << YAML::Value << plan.options.fps;
  out << YAML::Key << "frames" << YAML::Value << plan.frames;
  out << YAML::Key << "vehicle_path" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
      << "speed_mps" << YAML::Value << VehiclePath::kSpeedMps << YAML::Key << "yaw_rate_deg_per_s"
      << YAML::Value << VehiclePath::kYawRateRadPerS * kRadToDeg << YAML::EndMap;
  out << YAML::Key << "virtual_centre_m" << YAML::Value << YAML::Flow << YAML::BeginSeq
      << plan.virtualCentre[0] << plan.virtualCentre[1] << plan.virtualCentre[2] << YAML::EndSeq;
  out << YAML::Key << "panorama" << YAML::Value << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "width_px" << YAML::Value << plan.options.panoramaSize.width;
  out << YAML::Key << "height_px" << YAML::Value << plan.options.panoramaSize.height;
  out << YAML::Key << "azimuth_first_column_deg" << YAML::Value << -180;
  out << YAML::Key << "elevation_top_deg" << YAML::Value << 30;
  out << YAML::Key << "elevation_bottom_deg" << YAML::Value << -60;
  out << YAML::EndMap;
  if (plan.vehicle) {
    // Only with a body, so that recordings without one keep their bytes.
    out << YAML::Key << "ego_body" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "shape" << YAML::Value << "rounded box";
    out << YAML::Key << "corner_radius_m" << YAML::Value << EgoBody::kCornerRadiusM;
    out << YAML::Key << "edge_radius_m" << YAML::Value << EgoBody::kEdgeRadiusM;
    out << YAML::Key << "note" << YAML::Value
        << "cameras[].body_mask: 255 where the pixel's ray meets the body (rendered with a "
           "glossy roof); the panoramas leave the body out";
    out << YAML::EndMap;
  }

  out << YAML::Key << "cameras" << YAML::Value << YAML::BeginSeq;
  for (std::size_t c = 0; c < plan.cameras.size(); ++c) {
    const auto& camera = plan.cameras[c];
    const auto& p = camera.photometrics;
    const auto& name = camera.camera.calibration.name;
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << name;
    out << YAML::Key << "video" << YAML::Value << name + ".mkv";
    if (plan.vehicle) out << YAML::Key << "body_mask" << YAML::Value << bodyMaskName(name);
    out << YAML::Key << "photometrics" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "gain" << YAML::Value << p.gain;
    out << YAML::Key << "white_balance_bgr" << YAML::Value << YAML::Flow << YAML::BeginSeq
        << p.whiteBalance[0] << p.whiteBalance[1] << p.whiteBalance[2] << YAML::EndSeq;
    out << YAML::Key << "gamma" << YAML::Value << p.gamma;
    out << YAML::Key << "vignetting" << YAML::Value << p.vignetting;
    out << YAML::Key << "noise_sigma" << YAML::Value << p.noiseSigma;
    out << YAML::Key << "drift_amplitude" << YAML::Value << p.driftAmplitude;
    out << YAML::Key << "drift_period_s" << YAML::Value << p.driftPeriodS;
    out << YAML::Key << "drift_phase_rad" << YAML::Value << p.driftPhaseRad;
    out << YAML::EndMap;
    out << YAML::Key << "start_offset_ms" << YAML::Value << camera.startOffsetS * 1e3;
    out << YAML::Key << "jitter_ms" << YAML::Value << RecordingPlan::kJitterS * 1e3;
    out << YAML::Key << "drop_every" << YAML::Value << camera.dropEvery;
    if (camera.turnedPose) {
      // The mount before is the rig's; from turned_at_s on the camera sits as knocked.
      const auto angles = processing::mountAnglesFromRotation(camera.turnedPose->rotation);
      const cv::Vec3d& at = camera.turnedPose->position;
      out << YAML::Key << "turned_at_s" << YAML::Value << plan.frameTime(camera.turnFrame);
      out << YAML::Key << "mount_after_turn" << YAML::Value << YAML::Flow << YAML::BeginMap
          << YAML::Key << "x_m" << YAML::Value << at[0] << YAML::Key << "y_m" << YAML::Value
          << at[1] << YAML::Key << "z_m" << YAML::Value << at[2] << YAML::Key << "yaw_deg"
          << YAML::Value << angles.yawDeg << YAML::Key << "pitch_deg" << YAML::Value
          << angles.pitchDeg << YAML::Key << "roll_deg" << YAML::Value << angles.rollDeg
          << YAML::EndMap;
      if (plan.vehicle) {
        out << YAML::Key << "body_mask_after_turn" << YAML::Value << turnedBodyMaskName(name);
      }
    }
    out << YAML::Key << "frames_written" << YAML::Value << framesWritten[c];
    out << YAML::Key << "timestamps_us" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (int k = 0; k < plan.frames; ++k) {
      if (!plan.dropped(c, k)) out << plan.timestamp(c, k).count();
    }
    out << YAML::EndSeq;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;

  out << YAML::Key << "ground_truth_frames" << YAML::Value << YAML::BeginSeq;
  for (const int k : plan.groundTruthFrames) {
    const double t = plan.frameTime(k);
    const auto pose = VehiclePath::poseAt(t);
    out << YAML::BeginMap;
    out << YAML::Key << "frame" << YAML::Value << k;
    out << YAML::Key << "time_s" << YAML::Value << t;
    out << YAML::Key << "vehicle_pose" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
        << "x_m" << YAML::Value << pose.x << YAML::Key << "y_m" << YAML::Value << pose.y
        << YAML::Key << "yaw_deg" << YAML::Value << pose.yaw * kRadToDeg << YAML::EndMap;
    out << YAML::Key << "panorama" << YAML::Value << panoramaName(k);
    out << YAML::Key << "cameras" << YAML::Value << YAML::BeginMap;
    for (std::size_t c = 0; c < plan.cameras.size(); ++c) {
      const auto& name = plan.cameras[c].camera.calibration.name;
      out << YAML::Key << name << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
          << "image" << YAML::Value << cameraImageName(name, k) << YAML::Key << "exposure"
          << YAML::Value << plan.cameras[c].photometrics.exposureAt(t) << YAML::Key << "recorded"
          << YAML::Value << !plan.dropped(c, k) << YAML::EndMap;
    }
    out << YAML::EndMap;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::EndMap;
  writeText(file, out);
}

void writeManifest(const std::filesystem::path& file, const RecordingPlan& plan,
                   const std::map<std::string, double>& durationsS) {
  YAML::Emitter out;
  out << YAML::Comment(
      "Written last by surround-synth. A run with the same key (arguments, rig file, generator)\n"
      "finds this folder up to date and leaves it alone.");
  out << YAML::BeginMap;
  out << YAML::Key << "generator" << YAML::Value << "surround-synth";
  out << YAML::Key << "generator_version" << YAML::Value << std::string(kGeneratorVersion);
  out << YAML::Key << "key" << YAML::Value << plan.key;
  out << YAML::Key << "rig" << YAML::Value << plan.options.rig.string();
  out << YAML::Key << "arguments" << YAML::Value << plan.options.canonical();
  out << YAML::Key << "frames" << YAML::Value << plan.frames;
  out << YAML::Key << "durations_s" << YAML::Value << YAML::BeginMap;
  for (const auto& [stage, seconds] : durationsS) {
    out << YAML::Key << stage << YAML::Value << std::round(seconds * 1000) / 1000;
  }
  out << YAML::EndMap;
  out << YAML::EndMap;
  writeText(file, out);
}

std::optional<std::string> readManifestKey(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return std::nullopt;
  try {
    const YAML::Node root = YAML::LoadFile(file.string());
    if (root["key"]) return root["key"].as<std::string>();
  } catch (const YAML::Exception&) {
  }
  return std::nullopt;
}

}  // namespace surroundd::synth
