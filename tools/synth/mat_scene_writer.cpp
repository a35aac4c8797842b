#include "tools/synth/mat_scene_writer.hpp"

#include <fstream>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "tools/synth/calibration_mat.hpp"
#include "tools/synth/recording_plan.hpp"
#include "tools/synth/target_renderer.hpp"

namespace surroundd::synth {
namespace {

// Sub-pixel rays per pixel side: edges where the lens model puts them, as for the calibration
// tests.
constexpr int kSupersampling = 3;

}  // namespace

void writeMatScene(const SynthOptions& options, std::ostream& log) {
  std::error_code ec;
  if (std::filesystem::exists(options.out, ec) && !options.force) {
    throw UsageError(
        fmt::format("--out: '{}' exists; pass --force to replace it", options.out.string()));
  }
  const RecordingPlan plan = planRecording(options);
  std::vector<processing::CameraCalibration> cameras;
  for (const auto& camera : plan.cameras) cameras.push_back(camera.camera.calibration);
  processing::MatLayout mat;
  try {
    mat = groundMatAroundRig(cameras, {*options.calibrationMat, options.matAhead});
  } catch (const std::runtime_error& error) {
    throw UsageError(fmt::format("--calibration-mat: {}", error.what()));
  }
  std::filesystem::remove_all(options.out, ec);
  std::filesystem::create_directories(options.out);

  TargetScene scene;
  scene.floor = true;
  for (const auto& board : mat.boards) scene.targets.push_back(placeGroundMarker(board.print, 0));
  int frame = 0;
  for (const auto& camera : plan.cameras) {
    const auto& calibration = camera.camera.calibration;
    const TargetRenderer renderer(calibration.intrinsics, kSupersampling);
    const cv::Mat picture =
        renderer.render(calibration.pose, scene, camera.photometrics, options.seed, frame++);
    const auto file = options.out / (calibration.name + ".png");
    if (!cv::imwrite(file.string(), picture)) {
      throw std::runtime_error(fmt::format("{}: cannot write the picture", file.string()));
    }
  }
  std::vector<daemon::RigCamera> rig;
  for (const auto& camera : plan.cameras) rig.push_back(camera.camera);
  daemon::writeRigFile(options.out / "rig.yaml", rig,
                       fmt::format("Written by surround-synth from {} (seed {}): the exact "
                                   "calibration of the cameras that took the mat's pictures.",
                                   options.rig.filename().string(), options.seed));
  // The rig as its user has it before calibrating: the same lenses, the mounts measured by hand.
  for (auto& camera : rig) camera.calibration.pose = mountMeasuredByHand(camera.calibration.pose);
  daemon::writeRigFile(
      options.out / "nominal-rig.yaml", rig,
      "Written by surround-synth: the rig.yaml of these pictures with each mount a "
      "few centimetres and degrees off, as measured by hand before calibration.");
  std::ofstream(options.out / "mat.yaml")
      << matYaml(mat, fmt::format("The calibration mat surround-synth laid around {}: board "
                                  "centres and yaws on the ground, vehicle frame (x forward, y "
                                  "left, metres).",
                                  options.rig.filename().string()));
  log << fmt::format(
      "wrote {}: {} pictures of a mat of {} boards, mat.yaml, rig.yaml, nominal-rig.yaml\n",
      options.out.string(), plan.cameras.size(), mat.boards.size());
}

}  // namespace surroundd::synth
