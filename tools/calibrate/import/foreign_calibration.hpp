#pragma once
// One camera's calibration as another tool wrote it, gathered from its files before anything is
// converted: the lens's parts as found, and the pose in the source's own frame. Each part records
// where it came from ("file: key") for messages.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/lens/camera_model.hpp"
#include "tools/calibrate/import/import_options.hpp"
#include "tools/calibrate/import/source_frame.hpp"

namespace surroundd::calibrate {

template <typename Value>
struct Found {
  Value value;
  std::string origin;  // "file: key"
};

struct ForeignCalibration {
  std::optional<Found<cv::Mat>> cameraMatrix;  // CV_64F, 3x3 or 1x4 (fx, fy, cx, cy)
  std::optional<Found<std::vector<double>>> distortion;
  std::optional<Found<std::string>> modelName;
  std::optional<Found<cv::Size>> imageSize;
  std::optional<Found<processing::Intrinsics>> lens;  // complete (calib_results.txt)
  std::optional<Found<CameraFromSource>> pose;
  std::optional<Found<cv::Matx33d>> homography;  // ground canvas -> undistorted image
  // The undistorted image's camera matrix, where it is not K: K' = K with fx, fy scaled by
  // `scale_xy` and cx, cy shifted by `shift_xy` (the files of surround-view-system-introduction,
  // whose bird's-eye tool undistorts through K').
  std::optional<Found<cv::Vec2d>> undistortedScale;
  std::optional<Found<cv::Vec2d>> undistortedShift;
  std::vector<std::filesystem::path> files;  // what was read, for the rig's header
};

// Adds what an OpenCV FileStorage file (YAML, JSON or XML) holds to `into`, keeping parts already
// found (the first file that has a key wins). Keys are searched in nested maps too (see
// kImportUsage). Throws UsageError naming the file and key for unreadable or malformed input.
void readOpenCvCalibration(const std::filesystem::path& file, PoseDirection direction,
                           ForeignCalibration& into);

// A matrix written as an opencv-matrix node, a {rows, cols, data} map, or a (nested) list of
// numbers; nullopt when the node is none of these. CV_64F.
std::optional<cv::Mat> matrixFromNode(const cv::FileNode& node);

// The pose a transform gives, in the direction of P_camera = T * P_source.
CameraFromSource cameraFromSource(const cv::Matx33d& rotation, const cv::Vec3d& translation,
                                  PoseDirection direction);

}  // namespace surroundd::calibrate
