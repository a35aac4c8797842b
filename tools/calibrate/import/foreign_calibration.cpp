#include "tools/calibrate/import/foreign_calibration.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <opencv2/calib3d.hpp>

#include "common/nesting_depth.hpp"
#include "common/regular_file.hpp"
#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {
namespace {

using Keys = std::initializer_list<const char*>;

// docs/robustness.md: an imported calibration file of at most 16 MiB, nested at most 64 levels.
constexpr std::size_t kMaxCalibrationFileBytes = std::size_t{16} << 20;
constexpr std::size_t kMaxCalibrationDepth = 64;
constexpr int kMaxMatrixSide = 16;  // rows or columns of a matrix in a calibration file

constexpr Keys kCameraMatrixKeys{"camera_matrix", "cameraMatrix", "K", "cam_K", "intrinsic_matrix"};
constexpr Keys kDistortionKeys{"dist_coeffs", "distCoeffs", "distortion_coefficients",
                               "D",           "cam_dist",   "dist"};
constexpr Keys kModelKeys{"distortion_model", "camera_model", "lens_model"};
constexpr Keys kTransformKeys{"T", "sensor_calib", "T_cam_from_G", "extrinsic", "transform"};
constexpr Keys kRotationKeys{"R", "rotation", "rotation_matrix", "rvec", "rotation_vector"};
constexpr Keys kTranslationKeys{"t", "tvec", "translation", "translation_vector", "T"};
constexpr Keys kHomographyKeys{"H", "homography"};
// A homography the other way: from the undistorted image to the canvas.
constexpr Keys kProjectionKeys{"project_matrix"};

// The first of `keys` in `node` or, failing that, in its nested maps (depth first): tools wrap
// their matrices in maps of their own ("front_camera-intrinsic": {param: {cam_K: ...}}).
std::optional<std::pair<cv::FileNode, std::string>> findKey(const cv::FileNode& node, Keys keys,
                                                            std::size_t count = 0) {
  if (!node.isMap()) return std::nullopt;
  for (const char* key : keys) {
    const cv::FileNode child = node[key];
    if (child.empty() || child.isNone()) continue;
    // A key of the right name holding something else ("T" as a translation) is not this one.
    if (count != 0) {
      const auto matrix = matrixFromNode(child);
      if (!matrix || matrix->total() != count) continue;
    }
    return std::pair{child, std::string(key)};
  }
  for (const auto& child : node) {
    if (auto found = findKey(child, keys, count)) return found;
  }
  return std::nullopt;
}

bool collectNumbers(const cv::FileNode& node, std::vector<double>& values, int& depth) {
  if (node.isInt() || node.isReal()) {
    values.push_back(static_cast<double>(node));
    return true;
  }
  if (!node.isSeq()) return false;
  int inner = 0;
  for (const auto& child : node) {
    int childDepth = 0;
    if (!collectNumbers(child, values, childDepth)) return false;
    inner = std::max(inner, childDepth);
  }
  depth = inner + 1;
  return true;
}

cv::Mat matrixOf(const std::vector<double>& values, int rows) {
  if (rows <= 0 || values.empty() || values.size() % static_cast<std::size_t>(rows) != 0) {
    return {};
  }
  return cv::Mat(values, true).reshape(1, rows);
}

Found<cv::Mat> requireMatrix(const std::filesystem::path& file,
                             const std::pair<cv::FileNode, std::string>& found,
                             std::initializer_list<std::size_t> counts, std::string_view what) {
  const auto origin = fmt::format("{}: {}", file.string(), found.second);
  const auto matrix = matrixFromNode(found.first);
  const bool sized =
      matrix && std::find(counts.begin(), counts.end(), matrix->total()) != counts.end();
  if (!sized) {
    throw UsageError(fmt::format("{}: expected {}, got {}", origin, what,
                                 matrix ? fmt::format("{} numbers", matrix->total())
                                        : std::string("something that is not a matrix")));
  }
  if (!cv::checkRange(*matrix)) {
    throw UsageError(
        fmt::format("{}: expected {}, got a value that is not a finite number (NaN "
                    "or infinite)",
                    origin, what));
  }
  // Every key of 9 numbers is a 3x3 matrix (camera, rotation, homography), however the file wrote
  // it: as 3 rows or as one flat list (read as one row, whose (1, 1) lay past its end).
  return {matrix->total() == 9 ? matrix->reshape(1, 3) : *matrix, origin};
}

// A 3x3 matrix of a file (as requireMatrix shaped it).
cv::Matx33d matx33(const cv::Mat& matrix) {
  cv::Matx33d m;
  for (int i = 0; i < 9; ++i) m.val[i] = matrix.at<double>(i / 3, i % 3);
  return m;
}

cv::Matx33d rotationOf(const cv::Mat& matrix, const std::string& origin) {
  cv::Matx33d rotation;
  if (matrix.total() == 3) {
    cv::Rodrigues(matrix.reshape(1, 3), rotation);
    return rotation;
  }
  rotation = matx33(matrix);
  // Files round their matrices; the nearest rotation keeps the angles honest. Far from one, the
  // key holds something else.
  cv::Mat w, u, vt;
  cv::SVD::compute(cv::Mat(rotation), w, u, vt);
  const cv::Matx33d nearest(cv::Mat(u * vt));
  if (cv::norm(nearest - rotation, cv::NORM_INF) > 1e-2 || cv::determinant(nearest) < 0) {
    throw UsageError(fmt::format("{}: expected a rotation (orthonormal, determinant 1), got [{}]",
                                 origin, fmt::join(rotation.val, ", ")));
  }
  return nearest;
}

}  // namespace

std::optional<cv::Mat> matrixFromNode(const cv::FileNode& node) {
  if (node.isMap()) {
    if (!node["dt"].empty()) {  // opencv-matrix
      // OpenCV allocates what the header says before it reads the data: a damaged header asked
      // for 17 GB (found by import_fuzz). A calibration's matrices are a few numbers.
      const cv::FileNode rows = node["rows"], cols = node["cols"], data = node["data"];
      const auto side = [](const cv::FileNode& n) {
        return n.isInt() && static_cast<int>(n) >= 1 && static_cast<int>(n) <= kMaxMatrixSide;
      };
      if (!side(rows) || !side(cols) || !data.isSeq() ||
          data.size() != static_cast<std::size_t>(static_cast<int>(rows)) *
                             static_cast<std::size_t>(static_cast<int>(cols))) {
        return std::nullopt;
      }
      cv::Mat matrix;
      try {
        node >> matrix;
      } catch (const std::exception&) {  // cv::Exception, and what OpenCV lets through
        return std::nullopt;
      }
      if (matrix.empty() || matrix.channels() != 1) return std::nullopt;
      matrix.convertTo(matrix, CV_64F);
      return matrix;
    }
    if (node["data"].empty()) return std::nullopt;
    std::vector<double> values;
    int depth = 0;
    if (!collectNumbers(node["data"], values, depth)) return std::nullopt;
    const int rows = node["rows"].isInt() ? static_cast<int>(node["rows"])
                                          : (depth > 1 ? static_cast<int>(node["data"].size()) : 1);
    auto matrix = matrixOf(values, rows);
    return matrix.empty() ? std::nullopt : std::optional(matrix);
  }
  std::vector<double> values;
  int depth = 0;
  if (!collectNumbers(node, values, depth)) return std::nullopt;
  const int rows = depth > 1 ? static_cast<int>(node.size()) : 1;
  auto matrix = matrixOf(values, rows);
  return matrix.empty() ? std::nullopt : std::optional(matrix);
}

namespace {

// OpenCV's FileStorage reader is not made for files from anywhere: its parsers recurse per level
// (100 000 nested '[' overflowed the stack), and a malformed base64 block (YAML `!!binary`, JSON
// and XML `$base64$`) can loop forever. Refused here before it reads them, with what to change;
// real calibrations are a few kilobytes of plain numbers nested a few levels. The file is then
// opened again by name, as OpenCV tells YAML, JSON and XML apart by the name and the content.
void refuseWhatOpenCvCannotReadSafely(const std::filesystem::path& file) {
  std::string text;
  try {
    text = readRegularFile(file, kMaxCalibrationFileBytes);
  } catch (const FileReadError& error) {
    throw UsageError(error.what());
  }
  if (const std::size_t depth = nestingDepth(text); depth > kMaxCalibrationDepth) {
    throw UsageError(fmt::format("{}: nests {} levels deep; a calibration file needs at most {}",
                                 file.string(), depth, kMaxCalibrationDepth));
  }
  // A calibration is text: control characters (a NUL, say) are no part of one, and OpenCV's XML
  // parser crashed on a file with some (found by import_fuzz).
  if (const auto control = std::ranges::find_if(
          text,
          [](unsigned char c) {
            return (c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f;
          });
      control != text.end()) {
    throw UsageError(
        fmt::format("{}: holds a control character (byte {} at offset {}): not a text "
                    "file",
                    file.string(), static_cast<int>(static_cast<unsigned char>(*control)),
                    control - text.begin()));
  }
  if (text.find("!!binary") != std::string::npos || text.find("$base64$") != std::string::npos) {
    throw UsageError(fmt::format(
        "{}: holds base64-coded data (!!binary or $base64$), which is not read: write the "
        "calibration as plain numbers (cv::FileStorage without FileStorage::BASE64)",
        file.string()));
  }
}

}  // namespace

CameraFromSource cameraFromSource(const cv::Matx33d& rotation, const cv::Vec3d& translation,
                                  PoseDirection direction) {
  if (direction == PoseDirection::kToCamera) return {rotation, translation};
  return {rotation.t(), -(rotation.t() * translation)};
}

void readOpenCvCalibration(const std::filesystem::path& file, PoseDirection direction,
                           ForeignCalibration& into) {
  refuseWhatOpenCvCannotReadSafely(file);
  cv::FileStorage storage;
  try {
    storage.open(file.string(), cv::FileStorage::READ);
  } catch (const cv::Exception& error) {
    throw UsageError(fmt::format("{}: not an OpenCV FileStorage file (YAML, JSON or XML): {}",
                                 file.string(), error.err));
  } catch (const std::exception& error) {
    // OpenCV's parsers also let the standard library's own through (std::length_error from a
    // damaged YAML file: found by import_fuzz).
    throw UsageError(fmt::format("{}: not an OpenCV FileStorage file (YAML, JSON or XML): {}",
                                 file.string(), error.what()));
  }
  if (!storage.isOpened()) {
    throw UsageError(
        fmt::format("{}: cannot read it as an OpenCV FileStorage file (YAML, JSON "
                    "or XML)",
                    file.string()));
  }
  into.files.push_back(file);
  const cv::FileNode root = storage.root();
  if (!into.cameraMatrix) {
    if (const auto k = findKey(root, kCameraMatrixKeys)) {
      into.cameraMatrix =
          requireMatrix(file, *k, {9, 4}, "a 3x3 camera matrix or [fx, fy, cx, cy]");
    }
  }
  if (!into.distortion) {
    if (const auto d = findKey(root, kDistortionKeys)) {
      const auto m = requireMatrix(file, *d, {0, 4, 5, 8, 11, 12, 14},
                                   "distortion coefficients (4, 5, 8, 12 or 14; 11 for OCamCalib)");
      into.distortion = Found<std::vector<double>>{m.value.reshape(1, 1), m.origin};
    }
  }
  if (!into.modelName) {
    if (const auto m = findKey(root, kModelKeys); m && m->first.isString()) {
      into.modelName = Found<std::string>{std::string(m->first),
                                          fmt::format("{}: {}", file.string(), m->second)};
    }
  }
  if (!into.imageSize) {
    const std::array<std::pair<const char*, const char*>, 3> pairs{
        {{"image_width", "image_height"}, {"img_dist_w", "img_dist_h"}, {"width", "height"}}};
    for (const auto& [w, h] : pairs) {
      const auto width = findKey(root, {w});
      const auto height = findKey(root, {h});
      if (width && height && width->first.isInt() && height->first.isInt()) {
        into.imageSize =
            Found<cv::Size>{{static_cast<int>(width->first), static_cast<int>(height->first)},
                            fmt::format("{}: {}, {}", file.string(), w, h)};
        break;
      }
    }
    if (const auto size = findKey(root, {"image_size", "imageSize", "resolution"}, 2);
        !into.imageSize && size) {
      const auto m = requireMatrix(file, *size, {2}, "an image size: width and height");
      into.imageSize = Found<cv::Size>{
          imageSizeFrom(m.value.at<double>(0), m.value.at<double>(1), m.origin), m.origin};
    }
  }
  if (!into.pose && !into.homography) {
    if (const auto t = findKey(root, kTransformKeys, 16)) {
      const auto m = requireMatrix(file, *t, {16}, "a 4x4 matrix");
      into.pose = Found<CameraFromSource>{
          cameraFromSource(rotationOf(m.value.reshape(1, 4)(cv::Rect(0, 0, 3, 3)), m.origin),
                           {m.value.at<double>(3), m.value.at<double>(7), m.value.at<double>(11)},
                           direction),
          m.origin};
    } else if (const auto t34 = findKey(root, kTransformKeys, 12)) {
      const auto m = requireMatrix(file, *t34, {12}, "a 3x4 matrix");
      const cv::Mat rows = m.value.reshape(1, 3);
      into.pose = Found<CameraFromSource>{
          cameraFromSource(rotationOf(rows(cv::Rect(0, 0, 3, 3)).clone(), m.origin),
                           {rows.at<double>(0, 3), rows.at<double>(1, 3), rows.at<double>(2, 3)},
                           direction),
          m.origin};
    } else if (const auto r = findKey(root, kRotationKeys)) {
      const auto rotation =
          requireMatrix(file, *r, {3, 9}, "a rotation: a 3x3 matrix or a Rodrigues vector");
      const auto tKey = findKey(root, kTranslationKeys, 3);
      if (!tKey) {
        throw UsageError(fmt::format(
            "{}: has a rotation ('{}') but no translation of 3 numbers (t, tvec, translation)",
            file.string(), r->second));
      }
      const auto translation = requireMatrix(file, *tKey, {3}, "a translation of 3 numbers");
      const cv::Vec3d tv(translation.value.at<double>(0), translation.value.at<double>(1),
                         translation.value.at<double>(2));
      into.pose = Found<CameraFromSource>{
          cameraFromSource(rotationOf(rotation.value, rotation.origin), tv, direction),
          rotation.origin + " and " + tKey->second};
    } else if (const auto h = findKey(root, kHomographyKeys)) {
      const auto m = requireMatrix(file, *h, {9}, "a 3x3 homography");
      into.homography = Found<cv::Matx33d>{matx33(m.value), m.origin};
    } else if (const auto p = findKey(root, kProjectionKeys)) {
      const auto m = requireMatrix(file, *p, {9}, "a 3x3 homography");
      const cv::Matx33d projection = matx33(m.value);
      if (std::abs(cv::determinant(projection)) < 1e-12 * std::pow(cv::norm(projection), 3)) {
        throw UsageError(fmt::format("{}: the homography cannot be inverted", m.origin));
      }
      into.homography =
          Found<cv::Matx33d>{projection.inv(), m.origin +
                                                   " (inverted: it maps the picture to "
                                                   "the canvas)"};
    }
  }
  const auto pair = [&](const char* key, auto& found) {
    if (found) return;
    if (const auto k = findKey(root, {key})) {
      const auto m = requireMatrix(file, *k, {2}, "two numbers, for x and y");
      found = Found<cv::Vec2d>{{m.value.at<double>(0), m.value.at<double>(1)}, m.origin};
    }
  };
  pair("scale_xy", into.undistortedScale);
  pair("shift_xy", into.undistortedShift);
  if (into.undistortedScale &&
      (into.undistortedScale->value[0] <= 0 || into.undistortedScale->value[1] <= 0)) {
    throw UsageError(fmt::format("{}: expected two scales above 0, got {}, {}",
                                 into.undistortedScale->origin, into.undistortedScale->value[0],
                                 into.undistortedScale->value[1]));
  }
}

}  // namespace surroundd::calibrate
