#include "tools/calibrate/mat_command.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "daemon/rig_yaml.hpp"
#include "processing/calibration_error.hpp"
#include "tools/calibrate/calibration_output.hpp"
#include "tools/calibrate/camera_pictures.hpp"
#include "tools/calibrate/marker_file.hpp"
#include "tools/calibrate/mat_report.hpp"

namespace surroundd::calibrate {
namespace {

// The rig's cameras that the mat names, in rig order; every name in seen_by must be a camera.
std::vector<processing::CameraCalibration> matCameras(const ExtrinsicsOptions& options,
                                                      const processing::MatLayout& mat) {
  const auto rig = daemon::loadRigFile(options.rig);
  std::vector<std::string> names;
  names.reserve(rig.size());
  for (const auto& camera : rig) names.push_back(camera.calibration.name);
  for (std::size_t b = 0; b < mat.boards.size(); ++b) {
    for (const auto& camera : mat.boards[b].seenBy) {
      if (std::find(names.begin(), names.end(), camera) == names.end()) {
        throw UsageError(fmt::format(
            "{}: boards[{}].seen_by: no camera '{}' in {} (its cameras: "
            "{})",
            options.mat->string(), b, camera, options.rig.string(), fmt::join(names, ", ")));
      }
    }
  }
  std::vector<processing::CameraCalibration> cameras;
  for (const auto& camera : rig) {
    const bool named = std::any_of(mat.boards.begin(), mat.boards.end(), [&](const auto& board) {
      return std::find(board.seenBy.begin(), board.seenBy.end(), camera.calibration.name) !=
             board.seenBy.end();
    });
    if (named) cameras.push_back(camera.calibration);
  }
  return cameras;
}

cv::Mat readPicture(const ExtrinsicsOptions& options, const processing::CameraCalibration& camera) {
  const auto file = findPicture(*options.images, camera.name);
  if (!file) {
    throw UsageError(
        fmt::format("--images: {} holds no picture of camera '{}' (looked for {}.png, "
                    ".jpg, .jpeg, .bmp, .tif, .tiff)",
                    options.images->string(), camera.name, camera.name));
  }
  cv::Mat picture = cv::imread(file->string(), cv::IMREAD_GRAYSCALE);
  if (picture.empty()) {
    throw UsageError(fmt::format("--images: {}: cannot read the picture (not an image, or damaged)",
                                 file->string()));
  }
  const cv::Size lens = camera.intrinsics.imageSize;
  if (picture.size() != lens) {
    throw UsageError(fmt::format(
        "--images: {} is {}x{}, but camera '{}' in {} has a {}x{} lens; calibrate the intrinsics "
        "at this resolution first",
        file->string(), picture.cols, picture.rows, camera.name, options.rig.string(), lens.width,
        lens.height));
  }
  return picture;
}

}  // namespace

void runMatExtrinsics(const ExtrinsicsOptions& options, std::ostream& log) {
  const processing::MatLayout mat = loadMatFile(*options.mat);
  std::vector<processing::MatView> views;
  for (auto& camera : matCameras(options, mat)) {
    cv::Mat picture = readPicture(options, camera);
    views.push_back({std::move(camera), std::move(picture)});
  }
  processing::ExtrinsicSettings solve;
  solve.inlierThresholdPx = options.inlierPx;
  const auto result = processing::calibrateFromMat(mat, views, options.limits, {}, solve);
  printMatReport(mat, result, log);
  if (!result.passed()) {
    std::size_t failed = 0;
    for (const auto& camera : result.cameras) failed += camera.passed() ? 0 : 1;
    throw processing::CalibrationError(fmt::format(
        "{} of {} cameras failed, {} seam problems (see the table above); nothing was written",
        failed, result.cameras.size(), result.problems.size()));
  }
  std::vector<std::pair<std::string, processing::Pose>> mounts;
  for (const auto& camera : result.cameras) mounts.emplace_back(camera.camera, camera.solve->pose);
  const std::string comment = fmt::format(
      "Written by surround-calibrate extrinsics from the mat {} and the pictures in {}.",
      options.mat->string(), options.images->string());
  writeMountBlocks(options.out, mounts, comment);
  log << "wrote " << options.out.string() << "\n";
  if (options.updateRig) {
    for (const auto& [camera, pose] : mounts) {
      updateRigMount(options.rig, camera, pose, comment);
    }
    log << fmt::format("updated {} cameras in {}\n", mounts.size(), options.rig.string());
  }
}

}  // namespace surroundd::calibrate
