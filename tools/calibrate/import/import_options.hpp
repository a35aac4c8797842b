#pragma once
// Command line of `surround-calibrate import`: where a foreign calibration is, and the frame it is
// written in. The frame is never guessed: its axes, unit, ground and origin are stated by the user
// (see kImportUsage) and turned into the project's vehicle frame by source_frame.hpp.

#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/lens/camera_model.hpp"

namespace surroundd::calibrate {

// How a foreign pose matrix maps: `kToCamera` is P_camera = T * P_source (what solvePnP's
// rvec/tvec and the pjlab files hold), `kToSource` is the camera's pose in the source frame.
enum class PoseDirection { kToCamera, kToSource };

struct ImportOptions {
  // Exactly one kind of input.
  std::map<std::string, std::vector<std::filesystem::path>> cameraFiles;  // --camera NAME=F[,F]
  std::optional<std::filesystem::path> pjlabDir;   // intrinsic/<Cam>.json, extrinsic/<Cam>.json
  std::optional<std::filesystem::path> pjlabYaml;  // calibration.yaml (K, D, T_cam_from_G)
  std::optional<processing::LensModel> lens;       // otherwise from the file, or its coefficients
  std::optional<cv::Size> imageSize;               // otherwise from the file, or the image
  std::optional<double> fieldOfViewDeg;            // fisheye and ocam only
  // The source frame.
  cv::Matx33d axes = cv::Matx33d::eye();  // columns: source x, y, z in the vehicle frame
  std::string axesText = "forward,left,up";
  double unitM = 1;                               // metres per source unit
  double groundZ = 0;                             // source units, along the vertical axis
  std::map<std::string, double> groundZByCamera;  // overrides groundZ, rig camera names
  bool originCentre = false;
  cv::Vec3d offsetM;  // added to every position last, vehicle frame
  PoseDirection poseDirection = PoseDirection::kToCamera;
  // A ground homography's canvas: canvas pixel (u, v) is the source point
  // ((u - origin.x) * scale, (v - origin.y) * scale, groundZ).
  std::optional<double> canvasScale;  // source units per canvas pixel
  cv::Point2d canvasOrigin;
  // A canvas of this size whose cameras each have a strip of their own (canvas_strips.hpp); none:
  // every homography targets the whole canvas.
  std::optional<cv::Size> canvasStrips;
  // Output.
  std::filesystem::path out;
  std::optional<std::filesystem::path> images;  // folder of one still picture per camera
  std::string commandLine;                      // for the rig file's header
};

extern const std::string_view kImportUsage;

// `arguments` excludes "import". Throws UsageError.
ImportOptions parseImport(std::span<const std::string_view> arguments);

}  // namespace surroundd::calibrate
