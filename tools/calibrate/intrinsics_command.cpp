#include "tools/calibrate/intrinsics_command.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <numbers>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "processing/intrinsic_calibration.hpp"
#include "processing/target_detection.hpp"
#include "tools/calibrate/calibration_output.hpp"
#include "tools/calibrate/residual_plot.hpp"

namespace surroundd::calibrate {
namespace {

constexpr std::array<std::string_view, 9> kImageExtensions{".png",  ".jpg", ".jpeg", ".bmp", ".tif",
                                                           ".tiff", ".pgm", ".ppm",  ".pnm"};

// A pixel brighter than this in some image lies inside the lens's image circle; outside it a
// fisheye sensor sees only dark noise.
constexpr int kLitLevel = 16;

// A view whose error is this many times the median is worth a look (a blurred or bent board).
constexpr double kSuspectFactor = 3;

std::vector<std::filesystem::path> listImages(const std::filesystem::path& folder) {
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) {
    throw UsageError(
        fmt::format("--images: '{}' is not a folder ({})", folder.string(),
                    std::filesystem::exists(folder, ec) ? "a file" : "no such folder"));
  }
  std::vector<std::filesystem::path> images;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    std::string extension = entry.path().extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (entry.is_regular_file() && std::find(kImageExtensions.begin(), kImageExtensions.end(),
                                             extension) != kImageExtensions.end()) {
      images.push_back(entry.path());
    }
  }
  if (images.empty()) {
    throw UsageError(fmt::format("--images: '{}' holds no images (looked for {})", folder.string(),
                                 fmt::join(kImageExtensions, " ")));
  }
  std::sort(images.begin(), images.end());
  return images;
}

struct Detections {
  cv::Size imageSize;
  std::vector<processing::BoardView> views;
  std::vector<std::string> withoutBoard;
  cv::Mat lit;  // CV_8U, nonzero where some image is brighter than kLitLevel
};

// One image in memory at a time: a calibration set can be hundreds of large images.
Detections detectBoards(const std::vector<std::filesystem::path>& files, cv::Size board) {
  Detections found;
  for (const auto& file : files) {
    const cv::Mat gray = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
    if (gray.empty()) {
      throw UsageError(
          fmt::format("{}: cannot read the image (not an image, or damaged)", file.string()));
    }
    if (found.lit.empty()) {
      found.imageSize = gray.size();
      found.lit = cv::Mat::zeros(gray.size(), CV_8U);
    } else if (gray.size() != found.imageSize) {
      throw UsageError(fmt::format(
          "{}: the image is {}x{}, {} is {}x{}; the images must all come from one camera at one "
          "resolution",
          file.string(), gray.cols, gray.rows, files.front().string(), found.imageSize.width,
          found.imageSize.height));
    }
    found.lit |= gray > kLitLevel;
    if (auto corners = processing::findCheckerboard(gray, board)) {
      found.views.push_back({file.filename().string(), std::move(*corners)});
    } else {
      found.withoutBoard.push_back(file.filename().string());
    }
  }
  return found;
}

std::string viewNames(const std::vector<processing::BoardView>& views) {
  std::vector<std::string> names;
  names.reserve(views.size());
  for (const auto& view : views) names.push_back(view.name);
  return fmt::format("{}", fmt::join(names, ", "));
}

void report(const processing::IntrinsicCalibration& result, const Detections& found,
            std::size_t imageCount, std::ostream& log) {
  std::vector<double> errors;
  for (const auto& view : result.views) errors.push_back(view.rmsPx);
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  const double median = errors[errors.size() / 2];
  log << fmt::format("board found in {} of {} images; reprojection error per image (RMS):\n",
                     found.views.size(), imageCount);
  for (const auto& view : result.views) {
    log << fmt::format("  {:<32} {:7.3f} px{}\n", view.name, view.rmsPx,
                       view.rmsPx > kSuspectFactor * median ? "  <- well above the others" : "");
  }
  for (const auto& name : found.withoutBoard) log << fmt::format("  {:<32} no board\n", name);
  const auto& in = result.intrinsics;
  const bool fisheye = in.model == processing::LensModel::kFisheye;
  log << fmt::format("RMS {:.3f} px over {} corners\n", result.rmsPx,
                     result.views.size() * result.views.front().corners.size());
  log << fmt::format(
      "{}: fx {:.3f} fy {:.3f} cx {:.3f} cy {:.3f} px, distortion [{:.6g}]",
      fisheye ? "fisheye" : "pinhole", in.fx, in.fy, in.cx, in.cy,
      fmt::join(in.distortion.begin(), in.distortion.begin() + (fisheye ? 4 : 5), ", "));
  if (fisheye) {
    log << fmt::format(", field of view {:.1f} deg", in.maxFieldAngleRad * 360 / std::numbers::pi);
  }
  log << "\n";
}

}  // namespace

void runIntrinsics(const IntrinsicsOptions& options, std::ostream& log) {
  if (options.updateRig) rigCamera(*options.updateRig, options.camera);  // before the long part
  const auto files = listImages(options.images);
  const Detections found = detectBoards(files, options.board);
  if (found.views.empty()) {
    throw processing::CalibrationError(fmt::format(
        "no {}x{} checkerboard found in any of the {} images in '{}' (--board counts inner "
        "corners, where four squares meet: a board of 10x7 squares has 9x6)",
        options.board.width, options.board.height, files.size(), options.images.string()));
  }
  processing::IntrinsicCalibration result;
  try {
    result = processing::calibrateIntrinsics(options.model, found.imageSize, {options.board, 1.0},
                                             found.views);
  } catch (const processing::CalibrationError& error) {
    if (static_cast<int>(found.views.size()) >= processing::kMinimumBoardViews) throw;
    throw processing::CalibrationError(fmt::format(
        "{} (found in {}; not in {} other image{})", error.what(), viewNames(found.views),
        found.withoutBoard.size(), found.withoutBoard.size() == 1 ? "" : "s"));
  }
  auto& lens = result.intrinsics;
  if (lens.model == processing::LensModel::kFisheye) {
    // Within the polynomial's monotonic range, which calibrateIntrinsics() left in the field.
    lens.maxFieldAngleRad =
        std::min(lens.maxFieldAngleRad, options.fieldOfViewDeg
                                            ? *options.fieldOfViewDeg * std::numbers::pi / 360
                                            : processing::widestLitFieldAngle(lens, found.lit));
  }
  report(result, found, files.size(), log);

  const std::string comment = fmt::format(
      "Written by surround-calibrate intrinsics from {} of {} images in {} ({}x{} board):\n"
      "RMS reprojection error {:.3f} px.",
      found.views.size(), files.size(), options.images.string(), options.board.width,
      options.board.height, result.rmsPx);
  writeLensBlock(options.out, lens, comment);
  log << "wrote " << options.out.string() << "\n";
  if (options.residuals) {
    // The lens's lit area as a faint background shows where the corners did not reach.
    cv::Mat background(found.imageSize, CV_8UC3, cv::Scalar(0, 0, 0));
    background.setTo(cv::Scalar(48, 48, 48), found.lit);
    std::vector<ResidualSet> sets;
    for (std::size_t v = 0; v < result.views.size(); ++v) {
      const auto& view = result.views[v];
      sets.push_back({{view.corners.begin(), view.corners.end()},
                      {view.residuals.begin(), view.residuals.end()},
                      setColour(v)});
    }
    writeResidualPlot(*options.residuals, background, sets,
                      fmt::format("{} views, RMS {:.3f} px", sets.size(), result.rmsPx));
    log << "wrote " << options.residuals->string() << "\n";
  }
  if (options.updateRig) {
    updateRigLens(*options.updateRig, options.camera, lens, comment);
    log << fmt::format("updated camera '{}' in {}\n", options.camera, options.updateRig->string());
  }
}

}  // namespace surroundd::calibrate
