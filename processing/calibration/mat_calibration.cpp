#include "processing/calibration/mat_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>

#include "processing/calibration/calibration_error.hpp"
#include "processing/lens/camera_model.hpp"

namespace surroundd::processing {
namespace {

constexpr double kRadToDeg = 180 / std::numbers::pi;

void checkViews(const MatLayout& layout, std::span<const MatView> views) {
  for (const auto& board : layout.boards) {
    for (const auto& camera : board.seenBy) {
      const bool present = std::any_of(views.begin(), views.end(),
                                       [&](const MatView& v) { return v.nominal.name == camera; });
      if (!present) {
        throw CalibrationError(fmt::format(
            "board '{}' is seen by camera '{}', which has no picture", board.print.name, camera));
      }
    }
  }
  for (const auto& view : views) {
    if (view.gray.size() != view.nominal.intrinsics.imageSize || view.gray.type() != CV_8U) {
      throw CalibrationError(fmt::format("camera '{}': the picture is {}x{}, the lens {}x{}",
                                         view.nominal.name, view.gray.cols, view.gray.rows,
                                         view.nominal.intrinsics.imageSize.width,
                                         view.nominal.intrinsics.imageSize.height));
    }
  }
}

// Per-board RMS over the inliers, in the order of the sightings.
std::vector<MatBoardResidual> boardResiduals(const MatBoardDetection& detection,
                                             std::span<const PointCorrespondence> points,
                                             const ExtrinsicCalibration& solve) {
  std::vector<MatBoardResidual> boards;
  std::size_t first = 0;
  for (const auto& sighting : detection.found) {
    MatBoardResidual board{sighting.board, 0, 0};
    double sumSquares = 0;
    for (std::size_t i = first; i < first + sighting.pixels.size(); ++i) {
      if (!solve.inlier[i]) continue;
      const cv::Point2d residual = solve.reprojected[i] - points[i].pixel;
      sumSquares += residual.dot(residual);
      ++board.corners;
    }
    board.rmsPx = board.corners > 0 ? std::sqrt(sumSquares / board.corners) : 0;
    boards.push_back(board);
    first += sighting.pixels.size();
  }
  return boards;
}

// Every found board's corners with their place on the ground.
std::vector<PointCorrespondence> cornersOf(const MatLayout& layout,
                                           const MatBoardDetection& detection) {
  std::vector<PointCorrespondence> points;
  for (const auto& sighting : detection.found) {
    const GroundMarker& print = layout.boards[sighting.board].print;
    const auto corners = print.corners();
    for (std::size_t k = 0; k < corners.size(); ++k) {
      points.push_back({cv::Vec3d(corners[k]), cv::Point2d(sighting.pixels[k]),
                        fmt::format("board '{}' corner {}", print.name, k)});
    }
  }
  return points;
}

// The boards, looked for through the nominal mount (a tape's and a protractor's); where some are
// missed, looked for again through the pose the found ones give: a mount a few degrees off puts a
// board 5 m away half a metre from where the picture shows it, beyond the search's margin.
MatBoardDetection detectBoards(const MatLayout& layout, const MatView& view,
                               const MatLimits& limits, const MatDetectionSettings& detection,
                               const ExtrinsicSettings& settings) {
  MatBoardDetection first = findMatBoards(view.gray, layout, view.nominal, detection);
  const auto points = cornersOf(layout, first);
  if (first.missed.empty() || std::ssize(points) < limits.minCorners) return first;
  CameraCalibration found = view.nominal;
  try {
    ExtrinsicSettings withPrior = settings;
    withPrior.prior = view.nominal.pose;
    found.pose = calibrateExtrinsics(view.nominal.intrinsics, points, withPrior).pose;
  } catch (const CalibrationError&) {
    return first;  // the solve over what was found says why
  }
  MatBoardDetection again = findMatBoards(view.gray, layout, found, detection);
  return again.found.size() > first.found.size() ? again : first;
}

MatCameraResult calibrateCamera(const MatLayout& layout, const MatView& view,
                                const MatLimits& limits, const MatDetectionSettings& detection,
                                const ExtrinsicSettings& settings) {
  MatCameraResult result;
  result.camera = view.nominal.name;
  result.detection = detectBoards(layout, view, limits, detection, settings);
  for (const auto& miss : result.detection.missed) {
    result.problems.push_back(
        fmt::format("board '{}': {}", layout.boards[miss.board].print.name, miss.reason));
  }
  const std::vector<PointCorrespondence> points = cornersOf(layout, result.detection);
  result.corners = static_cast<int>(points.size());
  if (result.corners < limits.minCorners) {
    result.problems.push_back(fmt::format("too few corners: {}, at least {} are needed",
                                          result.corners, limits.minCorners));
    return result;
  }
  try {
    ExtrinsicSettings withPrior = settings;
    withPrior.prior = view.nominal.pose;
    result.solve = calibrateExtrinsics(view.nominal.intrinsics, points, withPrior);
  } catch (const CalibrationError& error) {
    result.problems.push_back(fmt::format("no pose: {}", error.what()));
    return result;
  }
  const ExtrinsicCalibration& solve = *result.solve;
  result.boards = boardResiduals(result.detection, points, solve);
  cv::Vec3d turn;
  cv::Rodrigues(solve.pose.rotation * view.nominal.pose.rotation.t(), turn);
  result.shiftM = cv::norm(solve.pose.position - view.nominal.pose.position);
  result.turnDeg = cv::norm(turn) * kRadToDeg;
  if (solve.rmsPx > limits.maxRmsPx) {
    result.problems.push_back(fmt::format(
        "reprojection RMS {:.2f} px is over the limit of {:g} px; a board's place, yaw or size in "
        "the layout may be wrong (see the per-board RMS)",
        solve.rmsPx, limits.maxRmsPx));
  }
  if (solve.inlierCount < result.corners) {
    result.problems.push_back(fmt::format("{} of {} corners miss by more than {:g} px",
                                          result.corners - solve.inlierCount, result.corners,
                                          settings.inlierThresholdPx));
  }
  if (result.shiftM > limits.maxShiftM || result.turnDeg > limits.maxTurnDeg) {
    result.problems.push_back(fmt::format(
        "implausible pose: {:.2f} m and {:.1f} degrees from the nominal mount (limits {:g} m, "
        "{:g} degrees)",
        result.shiftM, result.turnDeg, limits.maxShiftM, limits.maxTurnDeg));
  }
  return result;
}

// Where a camera's pixel meets the board's plane (z = `height`), through its solved pose.
std::optional<cv::Vec3d> onGround(const CameraModel& model, const Pose& pose, cv::Point2d pixel,
                                  double height) {
  const auto ray = model.unproject(pixel);
  if (!ray) return std::nullopt;
  const cv::Vec3d direction = pose.rotation * *ray;
  const double t = (height - pose.position[2]) / direction[2];
  if (!(t > 0)) return std::nullopt;
  return pose.position + t * direction;
}

const MatBoardSighting* sightingOf(const MatCameraResult& camera, std::size_t board) {
  for (const auto& sighting : camera.detection.found) {
    if (sighting.board == board) return &sighting;
  }
  return nullptr;
}

std::optional<MatSeam> seamOf(const MatLayout& layout, std::size_t board,
                              const MatCameraResult& first, const MatView& firstView,
                              const MatCameraResult& second, const MatView& secondView) {
  const auto* a = sightingOf(first, board);
  const auto* b = sightingOf(second, board);
  if (!a || !b || !first.solve || !second.solve) return std::nullopt;
  const CameraModel modelA(firstView.nominal.intrinsics), modelB(secondView.nominal.intrinsics);
  const double height = layout.boards[board].print.centre[2];
  MatSeam seam{board, first.camera, second.camera, 0, 0, 0};
  double sumSquares = 0;
  for (std::size_t k = 0; k < a->pixels.size(); ++k) {
    const auto pa = onGround(modelA, first.solve->pose, a->pixels[k], height);
    const auto pb = onGround(modelB, second.solve->pose, b->pixels[k], height);
    if (!pa || !pb) continue;
    const double cm = 100 * cv::norm(*pa - *pb);
    sumSquares += cm * cm;
    seam.maxCm = std::max(seam.maxCm, cm);
    ++seam.corners;
  }
  seam.rmsCm = seam.corners > 0 ? std::sqrt(sumSquares / seam.corners) : 0;
  return seam;
}

}  // namespace

bool MatCalibration::passed() const {
  return problems.empty() &&
         std::all_of(cameras.begin(), cameras.end(), [](const auto& c) { return c.passed(); });
}

MatCalibration calibrateFromMat(const MatLayout& layout, std::span<const MatView> views,
                                const MatLimits& limits, const MatDetectionSettings& detection,
                                const ExtrinsicSettings& solve) {
  checkViews(layout, views);
  MatCalibration result;
  for (const auto& view : views) {
    result.cameras.push_back(calibrateCamera(layout, view, limits, detection, solve));
  }
  const auto indexOf = [&](const std::string& camera) {
    return static_cast<std::size_t>(
        std::find_if(views.begin(), views.end(),
                     [&](const MatView& v) { return v.nominal.name == camera; }) -
        views.begin());
  };
  for (std::size_t b = 0; b < layout.boards.size(); ++b) {
    const MatBoard& board = layout.boards[b];
    if (board.seenBy.size() != 2) continue;
    const std::size_t i = indexOf(board.seenBy[0]), j = indexOf(board.seenBy[1]);
    const auto seam = seamOf(layout, b, result.cameras[i], views[i], result.cameras[j], views[j]);
    if (!seam) {
      const bool inFirst = sightingOf(result.cameras[i], b) != nullptr;
      const bool inSecond = sightingOf(result.cameras[j], b) != nullptr;
      result.problems.push_back(
          inFirst == inSecond
              ? fmt::format("seam {}|{} unchecked: board '{}' {}", board.seenBy[0], board.seenBy[1],
                            board.print.name,
                            inFirst ? "was found by both, but a pose is missing"
                                    : "was found by neither camera")
              : fmt::format("seam {}|{} unchecked: board '{}' was found by {} only, not by {}",
                            board.seenBy[0], board.seenBy[1], board.print.name,
                            inFirst ? board.seenBy[0] : board.seenBy[1],
                            inFirst ? board.seenBy[1] : board.seenBy[0]));
      continue;
    }
    if (seam->rmsCm > limits.maxSeamCm) {
      result.problems.push_back(fmt::format(
          "seam {}|{}: the cameras put board '{}' {:.1f} cm apart (RMS), over the limit of {:g} cm",
          seam->first, seam->second, board.print.name, seam->rmsCm, limits.maxSeamCm));
    }
    result.seams.push_back(*seam);
  }
  return result;
}

}  // namespace surroundd::processing
