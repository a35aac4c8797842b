#include "tools/calibrate/intrinsics/intrinsics_command.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <mutex>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "processing/calibration/calibration_coverage.hpp"
#include "processing/calibration/picture_search.hpp"
#include "processing/calibration/view_acceptance.hpp"
#include "tools/calibrate/calibration_output.hpp"
#include "tools/calibrate/intrinsics/intrinsics_report.hpp"
#include "tools/calibrate/lens_field.hpp"
#include "tools/calibrate/residual_plot.hpp"

namespace surroundd::calibrate {
namespace {

using processing::PictureSearch;

constexpr std::array<std::string_view, 9> kImageExtensions{".png",  ".jpg", ".jpeg", ".bmp", ".tif",
                                                           ".tiff", ".pgm", ".ppm",  ".pnm"};

std::vector<std::filesystem::path> listImages(const IntrinsicsOptions& options) {
  const auto& folder = options.images;
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
  for (const auto& name : options.exclude) {
    const auto excluded = std::remove_if(images.begin(), images.end(),
                                         [&](const auto& p) { return p.filename() == name; });
    if (excluded == images.end()) {
      throw UsageError(fmt::format("--exclude: no image '{}' in '{}'", name, folder.string()));
    }
    images.erase(excluded, images.end());
  }
  std::sort(images.begin(), images.end());
  return images;
}

struct Detections {
  cv::Size imageSize;
  std::vector<processing::BoardView> views;
  std::vector<std::string> notes;  // pictures not used, and why
  cv::Mat brightest;               // CV_8U, per pixel the brightest value over the pictures
};

std::string outcomeText(const PictureSearch& result) {
  switch (result.outcome) {
    case PictureSearch::Outcome::kFound:
      return fmt::format("{} corners, edges {:.1f} px wide", result.corners.size(),
                         result.edgeWidthPx);
    case PictureSearch::Outcome::kNotFound:
      return "no board";
    case PictureSearch::Outcome::kLargerThanBoard:
      return fmt::format("a {}x{} grid, larger than the board", result.seenGrid.width,
                         result.seenGrid.height);
    case PictureSearch::Outcome::kTimedOut:
      return "search given up (time bound)";
    case PictureSearch::Outcome::kNotSearched:
      return "not searched";
    case PictureSearch::Outcome::kUnreadable:
      return "cannot read the image";
  }
  return "?";
}

// Searches every picture in parallel, printing each as it is done; refuses unreadable pictures,
// mixed sizes and a board size the pictures contradict.
Detections detectBoards(const std::vector<std::filesystem::path>& files,
                        const IntrinsicsOptions& options, std::ostream& log) {
  Detections found;
  std::mutex brightestMutex;
  const auto load = [&](std::size_t index) {
    cv::Mat gray = cv::imread(files[index].string(), cv::IMREAD_GRAYSCALE);
    std::lock_guard lock(brightestMutex);
    if (!gray.empty() && found.brightest.empty()) found.brightest = gray.clone();
    if (!gray.empty() && gray.size() == found.brightest.size()) {
      cv::max(found.brightest, gray, found.brightest);
    }
    return gray;
  };
  processing::SearchOptions search;
  search.perPicture =
      std::chrono::milliseconds(static_cast<long long>(options.detectTimeoutS * 1000));
  log << fmt::format("looking for a {} in {} pictures\n", options.board.describe(), files.size());
  const auto results = processing::searchPictures(
      files.size(), load, options.board, search,
      [&](std::size_t index, const PictureSearch& result, std::size_t done) {
        log << fmt::format("  [{:>3}/{}] {}: {} ({:.1f} s)\n", done, files.size(),
                           files[index].filename().string(), outcomeText(result), result.seconds)
            << std::flush;
      });
  std::vector<std::string> largerGrids;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const auto& result = results[i];
    const std::string name = files[i].filename().string();
    if (result.outcome == PictureSearch::Outcome::kUnreadable) {
      throw UsageError(
          fmt::format("{}: cannot read the image (not an image, or damaged)", files[i].string()));
    }
    if (result.outcome == PictureSearch::Outcome::kNotSearched) continue;
    if (found.imageSize.area() == 0) {
      found.imageSize = result.imageSize;
    } else if (result.imageSize != found.imageSize && result.imageSize.area() > 0) {
      throw UsageError(fmt::format(
          "{}: the image is {}x{}, the others are {}x{}; the images must all come from one camera "
          "at one resolution",
          files[i].string(), result.imageSize.width, result.imageSize.height, found.imageSize.width,
          found.imageSize.height));
    }
    if (result.outcome == PictureSearch::Outcome::kLargerThanBoard) {
      largerGrids.push_back(
          fmt::format("{}x{} in {}", result.seenGrid.width, result.seenGrid.height, name));
    } else if (result.outcome == PictureSearch::Outcome::kTimedOut) {
      found.notes.push_back(
          fmt::format("{}: no board found within {:g} s of CPU time (--detect-timeout-s)", name,
                      options.detectTimeoutS));
    } else if (result.outcome == PictureSearch::Outcome::kFound) {
      processing::BoardView view{name, result.corners, result.grid, result.edgeWidthPx};
      if (const auto blurred = processing::blurProblem(view, options.limits)) {
        found.notes.push_back(fmt::format("{}: {}", name, *blurred));
      } else {
        found.views.push_back(std::move(view));
      }
    } else {
      found.notes.push_back(fmt::format("{}: no board", name));
    }
  }
  if (found.views.empty() && !largerGrids.empty()) {
    throw UsageError(fmt::format(
        "--board {}x{}: the pictures show a larger chessboard grid ({}); --board counts the "
        "inner corners, where four squares meet",
        options.board.size.width, options.board.size.height, fmt::join(largerGrids, ", ")));
  }
  return found;
}

// Duplicates leave the list, each with a note.
void dropDuplicates(Detections& found) {
  const auto duplicates = processing::findDuplicateViews(found.views);
  for (const auto& d : duplicates) {
    found.notes.push_back(fmt::format("{}: repeats {} (the board outlines overlap {:.0f} %)",
                                      found.views[d.view].name, found.views[d.of].name,
                                      100 * d.overlap));
  }
  for (auto d = duplicates.rbegin(); d != duplicates.rend(); ++d) {
    found.views.erase(found.views.begin() + static_cast<std::ptrdiff_t>(d->view));
  }
}

std::string viewNames(const std::vector<processing::BoardView>& views) {
  std::vector<std::string> names;
  names.reserve(views.size());
  for (const auto& view : views) names.push_back(view.name);
  return fmt::format("{}", fmt::join(names, ", "));
}

void writePictures(const IntrinsicsOptions& options, const processing::IntrinsicCalibration& result,
                   const processing::CoverageMap& coverage, const processing::ImageCircle& circle,
                   std::span<const processing::BoardView> views, std::ostream& log) {
  if (options.coverage) {
    writeCoveragePlot(*options.coverage, coverage, circle, views);
    log << "wrote " << options.coverage->string() << "\n";
  }
  if (options.residuals) {
    cv::Mat background(coverage.imageSize, CV_8UC3, cv::Scalar(0, 0, 0));
    background.setTo(cv::Scalar(48, 48, 48), circle.lit);
    std::vector<ResidualSet> sets;
    for (std::size_t v = 0; v < result.views.size(); ++v) {
      const auto& view = result.views[v];
      sets.push_back({{view.corners.begin(), view.corners.end()},
                      {view.residuals.begin(), view.residuals.end()},
                      setColour(v)});
    }
    writeResidualPlot(*options.residuals, background, sets,
                      fmt::format("{} views, RMS {:.3f} px", sets.size(), result.rmsPx),
                      options.residualScale);
    log << "wrote " << options.residuals->string() << "\n";
  }
}

}  // namespace

void runIntrinsics(const IntrinsicsOptions& options, std::ostream& log) {
  if (options.updateRig) rigCamera(*options.updateRig, options.camera);  // before the long part
  const auto files = listImages(options);
  Detections found = detectBoards(files, options, log);
  if (options.updateRig && found.imageSize.area() > 0) {
    checkRigPictureSize(*options.updateRig, options.camera, found.imageSize);  // before the solve
  }
  dropDuplicates(found);
  for (const auto& note : found.notes) log << "  skipped " << note << "\n";
  if (found.views.empty()) {
    throw processing::CalibrationError(fmt::format(
        "no {} found in any of the {} images in '{}' (--board counts inner corners, where four "
        "squares meet: a board of 10x7 squares has 9x6)",
        options.board.describe(), files.size(), options.images.string()));
  }
  if (static_cast<int>(found.views.size()) < options.limits.minViews) {
    throw processing::CalibrationError(fmt::format(
        "too few views: {} usable (found in {}), at least {} are needed (from different angles "
        "and field positions){}",
        found.views.size(), viewNames(found.views), options.limits.minViews,
        found.notes.empty() ? "" : fmt::format("; skipped: {}", fmt::join(found.notes, "; "))));
  }
  const auto robust = processing::calibrateLeavingOutBadViews(options.model, found.imageSize,
                                                              found.views, options.limits);
  auto result = robust.result;
  for (const auto& left : robust.leftOut) log << "  left out " << left << " (--max-view-rms-px)\n";
  std::vector<processing::BoardView> used;
  for (const auto& view : found.views) {
    if (std::any_of(result.views.begin(), result.views.end(),
                    [&](const auto& r) { return r.name == view.name; })) {
      used.push_back(view);
    }
  }
  const auto circle = lensCircle(options.model, found.brightest);
  const auto coverage = processing::coverageOf(used, found.imageSize, circle.lit);
  auto& lens = result.intrinsics;
  const auto field = limitField(lens, circle, used, options.fieldOfViewDeg);
  printViewTable(result, options.squareMm, options.limits, log);
  printLens(result, field, log);
  log << fmt::format("coverage {:.0f} % of the lens's cells", 100 * coverage.coveredShare);
  if (const auto parts = coverage.uncoveredParts(); !parts.empty()) {
    log << fmt::format("; no corners in {}", fmt::join(parts, ", "));
  }
  log << "\n";
  const auto verdict = processing::judgeCalibration(result, coverage.coveredShare, options.limits);
  printVerdict(verdict, log);
  if (!verdict.passed) {
    throw processing::CalibrationError(
        fmt::format("the solve failed its limits ({}); nothing was written",
                    fmt::join(verdict.failures, "; ")));
  }

  const std::string comment = fmt::format(
      "Written by surround-calibrate intrinsics from {} of {} images in {} ({}):\n"
      "RMS reprojection error {:.3f} px.",
      result.views.size(), files.size(), options.images.string(), options.board.describe(),
      result.rmsPx);
  // The pictures first: a picture that cannot be written then leaves no lens block behind that
  // looks like a finished run.
  writePictures(options, result, coverage, circle, used, log);
  writeLensBlock(options.out, lens, comment);
  log << "wrote " << options.out.string() << "\n";
  if (options.updateRig) {
    updateRigLens(*options.updateRig, options.camera, lens, comment);
    log << fmt::format("updated camera '{}' in {}\n", options.camera, options.updateRig->string());
  }
}

}  // namespace surroundd::calibrate
