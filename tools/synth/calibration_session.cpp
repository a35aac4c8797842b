#include "tools/synth/calibration_session.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "daemon/config/rig_yaml.hpp"
#include "tools/synth/calibration_scenes.hpp"
#include "tools/synth/photometrics.hpp"
#include "tools/synth/recording_plan.hpp"
#include "tools/synth/target_renderer.hpp"

namespace surroundd::synth {
namespace {

// Sub-pixel rays per pixel side: edges where the lens model puts them, as for the calibration
// tests (the session's truth is judged at a twentieth of a pixel too).
constexpr int kSupersampling = 3;
// Of each pose's share of the frames, this part carries the board over from the previous pose;
// the rest holds it still. A person moves the board in about the time they hold it.
constexpr double kCarryShare = 0.4;

// `a` moved toward `b` by `t` (0..1): positions on a line, rotations along the shortest turn.
processing::Pose between(const processing::Pose& a, const processing::Pose& b, double t) {
  cv::Vec3d turn;
  cv::Rodrigues(b.rotation * a.rotation.t(), turn);
  cv::Matx33d part;
  cv::Rodrigues(turn * t, part);
  return {part * a.rotation, a.position + t * (b.position - a.position)};
}

}  // namespace

void renderCalibrationSession(const processing::Intrinsics& lens, const SessionPlan& plan,
                              const std::function<void(int index, const cv::Mat& bgr)>& frame) {
  const auto poses = boardPosesCoveringField(lens, plan.board, plan.poses, plan.seed);
  const TargetRenderer renderer(lens, kSupersampling);
  const auto photometrics = randomPhotometrics(plan.seed, 0, plan.noiseSigma, false);
  const int count = static_cast<int>(poses.size());
  for (int k = 0; k < count; ++k) {
    const int first = k * plan.frames / count, end = (k + 1) * plan.frames / count;
    const int carried = k == 0 ? 0 : static_cast<int>((end - first) * kCarryShare);
    cv::Mat held;
    for (int index = first; index < end; ++index) {
      const int step = index - first;
      if (step >= carried && !held.empty()) {
        frame(index, held);  // still: the same picture (rendered once)
        continue;
      }
      const auto& target = poses[static_cast<std::size_t>(k)];
      const auto pose = step < carried ? between(poses[static_cast<std::size_t>(k) - 1], target,
                                                 (step + 1.0) / (carried + 1.0))
                                       : target;
      TargetScene scene;
      scene.targets.push_back(placeBoard(plan.board, pose));
      cv::Mat picture = renderer.render({}, scene, photometrics, plan.seed, index);
      if (step >= carried) held = picture;
      frame(index, picture);
    }
  }
}

void writeCalibrationSession(const SynthOptions& options, std::ostream& log) {
  std::error_code ec;
  if (std::filesystem::exists(options.out, ec) && !options.force) {
    throw UsageError(
        fmt::format("--out: '{}' exists; pass --force to replace it", options.out.string()));
  }
  auto cameras = daemon::loadRigFile(options.rig);
  const auto found = std::find_if(cameras.begin(), cameras.end(), [&](const auto& c) {
    return c.calibration.name == *options.calibrationSession;
  });
  if (found == cameras.end()) {
    std::vector<std::string> names;
    names.reserve(cameras.size());
    for (const auto& c : cameras) names.push_back(c.calibration.name);
    throw UsageError(fmt::format("--calibration-session: no camera '{}' in {} (it has {})",
                                 *options.calibrationSession, options.rig.string(),
                                 fmt::join(names, ", ")));
  }
  daemon::RigCamera camera = *found;
  auto& lens = camera.calibration.intrinsics;
  if (options.size) lens = scaleIntrinsics(lens, *options.size);
  SessionPlan plan;
  plan.frames = options.frameCount();
  plan.seed = options.seed;
  plan.noiseSigma = options.noiseSigma;
  if (plan.frames < 2 * plan.poses) {
    throw UsageError(fmt::format(
        "--calibration-session: {} frames cannot show {} board poses (at least {}: more "
        "--seconds or --fps)",
        plan.frames, plan.poses, 2 * plan.poses));
  }
  std::filesystem::remove_all(options.out, ec);
  std::filesystem::create_directories(options.out);
  renderCalibrationSession(lens, plan, [&](int index, const cv::Mat& bgr) {
    const auto file = options.out / fmt::format("frame_{:04d}.png", index);
    if (!cv::imwrite(file.string(), bgr)) {
      throw std::runtime_error(fmt::format("{}: cannot write the picture", file.string()));
    }
  });
  camera.source.reset();
  daemon::writeRigFile(
      options.out / "rig.yaml", std::span(&camera, 1),
      fmt::format("Written by surround-synth --calibration-session {} from {} (seed {}): the "
                  "true lens of the camera that took frame_%04d.png ({} frames at {:g} fps, a "
                  "{}x{} chessboard held at {} poses).",
                  camera.calibration.name, options.rig.filename().string(), options.seed,
                  plan.frames, options.fps, plan.board.innerCorners.width,
                  plan.board.innerCorners.height, plan.poses));
  log << fmt::format("wrote {} frames of {} ({}x{}) and rig.yaml to {}\n", plan.frames,
                     camera.calibration.name, lens.imageSize.width, lens.imageSize.height,
                     options.out.string());
}

}  // namespace surroundd::synth
