#include "tools/calibrate/extrinsics/mat_command.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "daemon/config/rig_yaml.hpp"
#include "processing/calibration/calibration_error.hpp"
#include "tools/calibrate/calibration_output.hpp"
#include "tools/calibrate/camera_pictures.hpp"
#include "tools/calibrate/extrinsics/mat_mounts_output.hpp"
#include "tools/calibrate/extrinsics/mat_report.hpp"
#include "tools/calibrate/marker_file.hpp"

namespace surroundd::calibrate {

std::vector<processing::CameraCalibration> matCameras(const std::filesystem::path& rigFile,
                                                      const std::filesystem::path& matFile,
                                                      const processing::MatLayout& mat) {
  const auto rig = daemon::loadRigFile(rigFile);
  std::vector<std::string> names;
  names.reserve(rig.size());
  for (const auto& camera : rig) names.push_back(camera.calibration.name);
  for (std::size_t b = 0; b < mat.boards.size(); ++b) {
    for (const auto& camera : mat.boards[b].seenBy) {
      if (std::find(names.begin(), names.end(), camera) == names.end()) {
        throw UsageError(
            fmt::format("{}: boards[{}].seen_by: no camera '{}' in {} (its cameras: "
                        "{})",
                        matFile.string(), b, camera, rigFile.string(), fmt::join(names, ", ")));
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

namespace {

cv::Mat readPicture(const ExtrinsicsOptions& options, const processing::CameraCalibration& camera) {
  const auto file = requirePicture(*options.images, camera.name);
  cv::Mat picture = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
  if (picture.empty()) {
    throw UsageError(fmt::format("--images: {}: cannot read the picture (not an image, or damaged)",
                                 file.string()));
  }
  checkPictureSize(file, picture.size(), camera, options.rig);
  return picture;
}

}  // namespace

void runMatExtrinsics(const ExtrinsicsOptions& options, std::ostream& log) {
  const processing::MatLayout mat = loadMatFile(*options.mat);
  std::vector<processing::MatView> views;
  for (auto& camera : matCameras(options.rig, *options.mat, mat)) {
    cv::Mat picture = readPicture(options, camera);
    views.push_back({std::move(camera), std::move(picture)});
  }
  processing::ExtrinsicSettings solve;
  solve.inlierThresholdPx = options.inlierPx;
  const auto result = processing::calibrateFromMat(mat, views, options.limits, {}, solve);
  printMatReport(mat, result, log);
  const std::string comment = fmt::format(
      "Written by surround-calibrate extrinsics from the mat {} and the pictures in {}.",
      options.mat->string(), options.images->string());
  MatMountTargets targets{options.out, std::nullopt};
  if (options.updateRig) targets.rig = options.rig;
  writeMatMounts(result, targets, comment, "see the table above");
  log << "wrote " << options.out.string() << "\n";
  if (options.updateRig) {
    log << fmt::format("updated {} cameras in {}\n", result.cameras.size(), options.rig.string());
  }
}

}  // namespace surroundd::calibrate
