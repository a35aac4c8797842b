#include "tools/synth/recording_plan.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "tools/synth/hash.hpp"

namespace surroundd::synth {
namespace {

constexpr std::uint64_t kTimingStream = 31;
constexpr std::uint64_t kJitterStream = 32;

std::string readFile(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

// The generator's own bytes: any change to the code that renders changes the key, so a cached
// recording is never silently stale after a rebuild.
std::uint64_t executableHash() {
  std::ifstream file("/proc/self/exe", std::ios::binary);
  std::vector<char> buffer(1 << 20);
  std::uint64_t h = fnv1a("");
  while (file) {
    file.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    h = fnv1a(std::string_view(buffer.data(), static_cast<std::size_t>(file.gcount())), h);
  }
  return h;
}

}  // namespace

processing::Intrinsics scaleIntrinsics(const processing::Intrinsics& in, cv::Size size) {
  processing::Intrinsics out = in;
  const double sx = static_cast<double>(size.width) / in.imageSize.width;
  const double sy = static_cast<double>(size.height) / in.imageSize.height;
  out.imageSize = size;
  out.fx = in.fx * sx;
  out.fy = in.fy * sy;
  out.cx = (in.cx + 0.5) * sx - 0.5;
  out.cy = (in.cy + 0.5) * sy - 0.5;
  if (in.model == processing::LensModel::kOcam) {
    // The sensor plane scales with the rows (the affine matrix keeps its 1 there), the columns'
    // extra through c and d; image_to_world's rays keep their directions: z(rho) scales with rho.
    out.ocam.c = in.ocam.c * sx / sy;
    out.ocam.d = in.ocam.d * sx / sy;
    for (auto& p : out.ocam.worldToImage) p *= sy;
    double scale = sy;  // sy^(1 - i)
    for (auto& a : out.ocam.imageToWorld) {
      a *= scale;
      scale /= sy;
    }
  }
  return out;
}

bool RecordingPlan::dropped(std::size_t camera, int frame) const {
  const int n = cameras[camera].dropEvery;
  return (n > 0 && frame % n == n - 1) ||
         cameras[camera].faulty(frame, SynthOptions::Fault::Kind::kStop);
}

std::chrono::microseconds RecordingPlan::timestamp(std::size_t camera, int frame) const {
  const double jitter = kJitterS * (2 * unitFromHash(hash64(options.seed, kJitterStream, camera,
                                                            static_cast<std::uint64_t>(frame))) -
                                    1);
  const double t = frameTime(frame) + cameras[camera].startOffsetS + jitter;
  return std::chrono::microseconds(std::max<std::int64_t>(0, std::llround(t * 1e6)));
}

RecordingPlan planRecording(const SynthOptions& options) {
  RecordingPlan plan;
  plan.options = options;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(options.rig, ec)) {
    throw UsageError(fmt::format(
        "--rig: expected a rig YAML file, got '{}' ({})", options.rig.string(),
        std::filesystem::exists(options.rig, ec) ? "not a regular file" : "no such file"));
  }
  plan.rigText = readFile(options.rig);
  std::vector<daemon::RigCamera> rig;
  try {
    auto file = daemon::loadRig(options.rig);
    rig = std::move(file.cameras);
    if (options.body) plan.vehicle = file.vehicle;
  } catch (const daemon::ConfigError& error) {
    std::string message = fmt::format("--rig: '{}' is not a valid rig:", options.rig.string());
    for (const auto& line : error.messages()) message += "\n  " + line;
    throw UsageError(message);
  }
  double heightSum = 0;
  for (std::size_t i = 0; i < rig.size(); ++i) {
    CameraPlan camera;
    camera.camera.calibration = rig[i].calibration;
    auto& intrinsics = camera.camera.calibration.intrinsics;
    if (options.size) intrinsics = scaleIntrinsics(intrinsics, *options.size);
    if (intrinsics.imageSize.width % 2 != 0 || intrinsics.imageSize.height % 2 != 0) {
      throw UsageError(fmt::format("--rig: camera '{}' has an odd image size {}x{}; pass --size",
                                   camera.camera.calibration.name, intrinsics.imageSize.width,
                                   intrinsics.imageSize.height));
    }
    const int index = static_cast<int>(i);
    switch (options.photometrics) {
      case SynthOptions::Photometrics::kRandom:
        camera.photometrics =
            randomPhotometrics(options.seed, index, options.noiseSigma, options.drift);
        break;
      case SynthOptions::Photometrics::kIdentity:
        camera.photometrics = identityPhotometrics();
        break;
      case SynthOptions::Photometrics::kExtreme:
        camera.photometrics =
            extremePhotometrics(options.seed, index, options.noiseSigma, options.drift,
                                camera.camera.calibration.role == processing::ColourRole::kSource);
        break;
    }
    HashRng timing(options.seed, kTimingStream * 1000 + i);
    camera.startOffsetS = timing.uniform(0, 0.004);
    heightSum += camera.camera.calibration.pose.position[2];
    plan.cameras.push_back(std::move(camera));
  }
  for (const auto& fault : options.faults) {
    const auto it = std::find_if(plan.cameras.begin(), plan.cameras.end(), [&](const auto& c) {
      return c.camera.calibration.name == fault.camera;
    });
    if (it == plan.cameras.end()) {
      throw UsageError(fmt::format("--fault: the rig has no camera named '{}'", fault.camera));
    }
    it->fault = fault.kind;
    it->faultFrame = static_cast<int>(std::lround(fault.fromS * options.fps));
  }
  for (const auto& turn : options.turns) {
    const auto it = std::find_if(plan.cameras.begin(), plan.cameras.end(), [&](const auto& c) {
      return c.camera.calibration.name == turn.camera;
    });
    if (it == plan.cameras.end()) {
      throw UsageError(fmt::format("--turn: the rig has no camera named '{}'", turn.camera));
    }
    const processing::Pose& pose = it->camera.calibration.pose;
    const processing::MountAngles before = processing::mountAnglesFromRotation(pose.rotation);
    it->turnedPose =
        processing::Pose{processing::rotationFromMountAngles({before.yawDeg + turn.byDeg.yawDeg,
                                                              before.pitchDeg + turn.byDeg.pitchDeg,
                                                              before.rollDeg + turn.byDeg.rollDeg}),
                         pose.position};
    it->turnFrame = static_cast<int>(std::lround(turn.atS * options.fps));
  }
  for (const auto& [name, n] : options.dropEvery) {
    const std::string& wanted = name;  // clang-tidy (clang 14) cannot capture the binding
    const auto it = std::find_if(plan.cameras.begin(), plan.cameras.end(), [&](const auto& c) {
      return c.camera.calibration.name == wanted;
    });
    if (it == plan.cameras.end()) {
      throw UsageError(fmt::format("--drop-every: the rig has no camera named '{}'", name));
    }
    it->dropEvery = n;
  }
  plan.frames = options.frameCount();
  const std::vector<int> defaults{0, plan.frames / 2, plan.frames - 1};
  const auto& chosen = options.groundTruthFrames ? *options.groundTruthFrames : defaults;
  const std::set<int> unique(chosen.begin(), chosen.end());
  plan.groundTruthFrames.assign(unique.begin(), unique.end());
  plan.virtualCentre = {0, 0, heightSum / static_cast<double>(plan.cameras.size())};
  const std::uint64_t key =
      fnv1a(plan.rigText, fnv1a(options.canonical(), fnv1a(kGeneratorVersion, executableHash())));
  plan.key = fmt::format("{:016x}", key);
  return plan;
}

}  // namespace surroundd::synth
