#include "tools/calibrate/import/foreign_lens.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {
namespace {

using processing::LensModel;

// A picture's pixels at or below this level are outside the lens's image circle (as
// surround-calibrate intrinsics takes it).
constexpr int kLitLevel = 16;
// Real pictures are rarely black outside the image circle (JPEG's dark level, stray light: the
// pjlab samples are lit to their corners), and a polynomial fitted inside the circle means nothing
// beyond it: the default field stops at the widest automotive fisheye lenses'.
constexpr double kWidestDefaultFieldDeg = 200;

std::optional<LensModel> modelFromName(std::string name) {
  std::ranges::transform(name, name.begin(), [](unsigned char c) { return std::tolower(c); });
  for (const auto* word : {"fisheye", "equidistant", "kannala_brandt", "kannala-brandt", "kb4"}) {
    if (name == word) return LensModel::kFisheye;
  }
  for (const auto* word : {"pinhole", "plumb_bob", "radtan", "radial-tangential", "rational"}) {
    if (name == word) return LensModel::kPinhole;
  }
  if (name == "ocam" || name == "ocamcalib" || name == "scaramuzza") return LensModel::kOcam;
  return std::nullopt;
}

LensModel chooseModel(const std::string& camera, const ForeignCalibration& found,
                      const ImportOptions& options) {
  if (options.lens) return *options.lens;
  if (found.modelName) {
    if (const auto model = modelFromName(found.modelName->value)) return *model;
    throw UsageError(fmt::format(
        "{}: unknown lens model '{}' (expected fisheye, equidistant, kannala_brandt, pinhole, "
        "plumb_bob, radtan or ocam); say which with --lens",
        found.modelName->origin, found.modelName->value));
  }
  const auto& d = found.distortion->value;
  if (d.size() == 5 || std::ranges::all_of(d, [](double k) { return k == 0; })) {
    return LensModel::kPinhole;
  }
  throw UsageError(fmt::format(
      "camera '{}': {} has {} distortion coefficients, which fit more than one lens model, and "
      "no file names the model; say which with --lens pinhole|fisheye|ocam",
      camera, found.distortion->origin, d.size()));
}

// Coefficients past `kept` must be zero: the project's models have no more (OpenCV's rational and
// thin-prism terms, for instance).
void requireZeroPast(const Found<std::vector<double>>& d, std::size_t kept,
                     std::string_view model) {
  for (std::size_t i = kept; i < d.value.size(); ++i) {
    if (d.value[i] != 0) {
      throw UsageError(fmt::format(
          "{}: the {} model takes {} coefficients, but coefficient {} is {} (not 0); its lens "
          "model is another",
          d.origin, model, kept, i + 1, d.value[i]));
    }
  }
}

std::string filesOf(const ForeignCalibration& found) {
  std::string text;
  for (const auto& file : found.files) text += (text.empty() ? "" : ", ") + file.string();
  return text.empty() ? "its files" : text;
}

}  // namespace

double fieldToImageCorner(const processing::Intrinsics& lens) {
  const bool ocam = lens.model == LensModel::kOcam;
  const auto& o = lens.ocam;
  // The farthest image corner from the centre, in the radial function's own units: the
  // normalized image (fisheye) or the sensor plane before the affine matrix (ocam).
  double corner = 0;
  for (const double x : {0.0, lens.imageSize.width - 1.0}) {
    for (const double y : {0.0, lens.imageSize.height - 1.0}) {
      const double u = x - lens.cx, v = y - lens.cy;
      const double determinant = o.c - o.d * o.e;
      corner = std::max(
          corner, ocam ? std::hypot((u - o.d * v) / determinant, (o.c * v - o.e * u) / determinant)
                       : std::hypot(u / lens.fx, v / lens.fy));
    }
  }
  const auto radial = [&](double offAxis) {
    if (ocam) {
      double rho = 0, power = 1;
      for (const double p : o.worldToImage) {
        rho += p * power;
        power *= offAxis - std::numbers::pi / 2;
      }
      return rho;
    }
    const auto& k = lens.distortion;
    const double t2 = offAxis * offAxis;
    return offAxis * (1 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
  };
  double previous = radial(0);
  constexpr double kStep = 0.1 * std::numbers::pi / 180;
  for (double offAxis = kStep; offAxis < std::numbers::pi; offAxis += kStep) {
    const double radius = radial(offAxis);
    if (radius >= corner || radius <= previous) return 2 * offAxis * 180 / std::numbers::pi;
    previous = radius;
  }
  return 360;
}

double litFieldDeg(const processing::Intrinsics& lens, const cv::Mat& picture) {
  // Unprojected with the widest field the image allows, then cut back to what is lit. The
  // farthest lit pixel of a row from the centre is its first or last one, and the off-axis angle
  // grows with that distance, so the rows' ends decide.
  processing::Intrinsics wide = lens;
  wide.maxFieldAngleRad = fieldToImageCorner(lens) * std::numbers::pi / 360;
  const processing::CameraModel model(wide);
  cv::Mat gray;
  if (picture.channels() == 1) {
    gray = picture;
  } else {
    cv::cvtColor(picture, gray, picture.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  }
  double widest = 0;
  for (int y = 0; y < gray.rows; ++y) {
    const auto* row = gray.ptr<std::uint8_t>(y);
    int first = 0, last = gray.cols - 1;
    while (first < gray.cols && row[first] <= kLitLevel) ++first;
    while (last > first && row[last] <= kLitLevel) --last;
    for (const int x : {first, last}) {
      if (x >= gray.cols || row[x] <= kLitLevel) continue;
      if (const auto ray = model.unproject(cv::Point2d(x, y))) {
        widest = std::max(widest, std::acos(std::clamp((*ray)[2], -1.0, 1.0)));
      }
    }
  }
  return widest > 0 ? 2 * widest * 180 / std::numbers::pi : fieldToImageCorner(lens);
}

processing::Intrinsics importedLens(const std::string& camera, const ForeignCalibration& found,
                                    const ImportOptions& options, const cv::Mat& picture) {
  const std::optional<cv::Size> pictureSize =
      picture.empty() ? std::nullopt : std::optional(picture.size());
  processing::Intrinsics lens;
  if (found.lens) {
    lens = found.lens->value;
  } else {
    if (!found.cameraMatrix) {
      throw UsageError(fmt::format(
          "camera '{}': no camera matrix in {} (keys camera_matrix, cameraMatrix, K, cam_K, "
          "intrinsic_matrix)",
          camera, filesOf(found)));
    }
    if (!found.distortion) {
      throw UsageError(fmt::format(
          "camera '{}': no distortion coefficients in {} (keys dist_coeffs, distCoeffs, "
          "distortion_coefficients, D, cam_dist, dist)",
          camera, filesOf(found)));
    }
    lens.model = chooseModel(camera, found, options);
    const cv::Mat& k = found.cameraMatrix->value;
    const auto& d = *found.distortion;
    if (lens.model == LensModel::kOcam) {
      // [[c, d, xc], [e, 1, yc]] in image order, as the pjlab layout writes OCamCalib's lens.
      if (k.total() != 9) {
        throw UsageError(fmt::format("{}: an ocam lens needs [[c, d, xc], [e, 1, yc], [0, 0, 1]]",
                                     found.cameraMatrix->origin));
      }
      lens.ocam.c = k.at<double>(0, 0);
      lens.ocam.d = k.at<double>(0, 1);
      lens.ocam.e = k.at<double>(1, 0);
      lens.cx = k.at<double>(0, 2);
      lens.cy = k.at<double>(1, 2);
      lens.ocam.worldToImage = d.value;
    } else {
      const bool full = k.total() == 9;
      lens.fx = full ? k.at<double>(0, 0) : k.at<double>(0);
      lens.fy = full ? k.at<double>(1, 1) : k.at<double>(1);
      lens.cx = full ? k.at<double>(0, 2) : k.at<double>(2);
      lens.cy = full ? k.at<double>(1, 2) : k.at<double>(3);
      if (full && std::abs(k.at<double>(0, 1)) > 1e-9 * lens.fx) {
        throw UsageError(fmt::format("{}: a skewed camera matrix (K[0][1] = {}) is not supported",
                                     found.cameraMatrix->origin, k.at<double>(0, 1)));
      }
      const bool fisheye = lens.model == LensModel::kFisheye;
      requireZeroPast(d, fisheye ? 4 : 5, fisheye ? "fisheye" : "pinhole");
      std::copy_n(d.value.begin(), std::min<std::size_t>(d.value.size(), fisheye ? 4 : 5),
                  lens.distortion.begin());
    }
  }
  if (options.imageSize) {
    lens.imageSize = *options.imageSize;
  } else if (!found.lens && found.imageSize) {
    lens.imageSize = found.imageSize->value;
  } else if (!found.lens && pictureSize) {
    lens.imageSize = *pictureSize;
  } else if (!found.lens) {
    throw UsageError(fmt::format(
        "camera '{}': no image size in {} (keys image_width and image_height, img_dist_w and "
        "img_dist_h, image_size); give --image-size WxH or the pictures with --images",
        camera, filesOf(found)));
  }
  if (processing::isWideAngle(lens.model)) {
    const double degrees =
        options.fieldOfViewDeg
            ? *options.fieldOfViewDeg
            : std::min(kWidestDefaultFieldDeg,
                       picture.empty() ? fieldToImageCorner(lens) : litFieldDeg(lens, picture));
    lens.maxFieldAngleRad = degrees * std::numbers::pi / 360;
  } else if (options.fieldOfViewDeg) {
    throw UsageError(fmt::format(
        "--field-of-view-deg: only a fisheye or ocam lens takes it, and camera '{}' is a pinhole",
        camera));
  }
  return lens;
}

}  // namespace surroundd::calibrate
