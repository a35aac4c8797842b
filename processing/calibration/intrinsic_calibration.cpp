#include "processing/calibration/intrinsic_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>

namespace surroundd::processing {
namespace {

// Both solvers run until a step changes nothing in double precision (or 200 iterations): a solve
// takes milliseconds, and stopping early would leave error that the corners do not have.
cv::TermCriteria solverCriteria() {
  return {cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200,
          std::numeric_limits<double>::epsilon()};
}

std::vector<cv::Point3f> gridPoints(const BoardView& view) {
  std::vector<cv::Point3f> points;
  points.reserve(view.grid.size());
  for (const auto& g : view.grid)
    points.emplace_back(static_cast<float>(g.x), static_cast<float>(g.y), 0.0f);
  return points;
}

ViewResiduals residualsOf(const CameraModel& model, const BoardView& view,
                          const std::vector<cv::Point3f>& pattern, const cv::Vec3d& rvec,
                          const cv::Vec3d& tvec) {
  ViewResiduals out;
  out.name = view.name;
  out.edgeWidthPx = view.edgeWidthPx;
  cv::Rodrigues(rvec, out.boardInCamera.rotation);
  out.boardInCamera.position = tvec;
  out.corners = view.corners;
  double sumSquares = 0;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    const auto pixel =
        model.project(out.boardInCamera.toVehicle({pattern[i].x, pattern[i].y, pattern[i].z}));
    // A corner the solved model cannot see at all is as wrong as it gets; report it as such.
    const cv::Point2f residual = pixel ? cv::Point2f(*pixel) - view.corners[i]
                                       : cv::Point2f(std::numeric_limits<float>::infinity(), 0.0f);
    out.residuals.push_back(residual);
    sumSquares += residual.dot(residual);
  }
  out.rmsPx = std::sqrt(sumSquares / static_cast<double>(pattern.size()));
  return out;
}

double widestAngle(const ViewResiduals& view, const std::vector<cv::Point3f>& pattern) {
  double widest = 0;
  for (const auto& p : pattern) {
    const cv::Vec3d x = view.boardInCamera.toVehicle({p.x, p.y, p.z});
    widest = std::max(widest, std::atan2(std::hypot(x[0], x[1]), x[2]));
  }
  return widest;
}

}  // namespace

IntrinsicCalibration calibrateIntrinsics(LensModel model, cv::Size imageSize,
                                         std::span<const BoardView> views) {
  if (static_cast<int>(views.size()) < kMinimumBoardViews) {
    throw CalibrationError(
        fmt::format("too few views: a board was found in {} image{}, at least "
                    "{} are needed (from different angles and field positions)",
                    views.size(), views.size() == 1 ? "" : "s", kMinimumBoardViews));
  }
  std::vector<std::vector<cv::Point3f>> objectPoints;
  std::vector<std::vector<cv::Point2f>> imagePoints;
  for (const auto& view : views) {
    objectPoints.push_back(gridPoints(view));
    imagePoints.push_back(view.corners);
  }

  IntrinsicCalibration result;
  Intrinsics in;
  in.model = model;
  in.imageSize = imageSize;
  std::vector<cv::Vec3d> rvecs, tvecs;
  try {
    if (model == LensModel::kPinhole) {
      // What calibrateCamera starts from (it calls the same function).
      result.startingFocalPx =
          cv::initCameraMatrix2D(objectPoints, imagePoints, imageSize).at<double>(0, 0);
      cv::Matx33d k;
      cv::Mat d, deviationsIntrinsics, deviationsExtrinsics, perViewErrors;
      cv::calibrateCamera(objectPoints, imagePoints, imageSize, k, d, rvecs, tvecs,
                          deviationsIntrinsics, deviationsExtrinsics, perViewErrors, 0,
                          solverCriteria());
      for (int i = 0; i < 5; ++i) in.distortion[static_cast<std::size_t>(i)] = d.at<double>(i);
      in.fx = k(0, 0), in.fy = k(1, 1), in.cx = k(0, 2), in.cy = k(1, 2);
      // Order: fx fy cx cy k1 k2 p1 p2 k3 ...
      const auto deviation = [&](int i) { return deviationsIntrinsics.at<double>(i); };
      auto& u = result.uncertainty;
      u.fx = deviation(0), u.fy = deviation(1), u.cx = deviation(2), u.cy = deviation(3);
      for (int i = 0; i < 5; ++i) u.distortion[static_cast<std::size_t>(i)] = deviation(4 + i);
    } else {
      // cv::fisheye::calibrate starts every solve from f = the larger image side / pi.
      result.startingFocalPx = std::max(imageSize.width, imageSize.height) / std::numbers::pi;
      cv::Matx33d k;
      cv::Vec4d d;
      cv::fisheye::calibrate(objectPoints, imagePoints, imageSize, k, d, rvecs, tvecs,
                             cv::fisheye::CALIB_RECOMPUTE_EXTRINSIC | cv::fisheye::CALIB_FIX_SKEW,
                             solverCriteria());
      for (int i = 0; i < 4; ++i) in.distortion[static_cast<std::size_t>(i)] = d[i];
      in.fx = k(0, 0), in.fy = k(1, 1), in.cx = k(0, 2), in.cy = k(1, 2);
      // As wide as the polynomial stays monotonic; fieldOfViewOf() narrows it to the lens.
      in.maxFieldAngleRad = std::numbers::pi;
      result.uncertainty = fisheyeUncertainty(in, objectPoints, imagePoints, rvecs, tvecs);
    }
  } catch (const cv::Exception& error) {
    throw CalibrationError(fmt::format("the solver failed: {}", error.err));
  }
  const CameraModel camera(in);
  result.intrinsics = camera.intrinsics();
  double sumSquares = 0;
  std::size_t count = 0;
  for (std::size_t v = 0; v < views.size(); ++v) {
    result.views.push_back(residualsOf(camera, views[v], objectPoints[v], rvecs[v], tvecs[v]));
    result.widestCornerAngleRad =
        std::max(result.widestCornerAngleRad, widestAngle(result.views.back(), objectPoints[v]));
    for (const auto& r : result.views.back().residuals) sumSquares += r.dot(r);
    count += objectPoints[v].size();
  }
  result.rmsPx = std::sqrt(sumSquares / static_cast<double>(count));
  return result;
}

LitFieldAngle widestLitFieldAngle(const Intrinsics& intrinsics, const cv::Mat& litMask) {
  // The field angle grows with the normalized radius, so the farthest lit pixel decides.
  const CameraModel model(intrinsics);
  const cv::Point2d centre(intrinsics.cx, intrinsics.cy);
  double farthest = -1;
  cv::Point2d pixel = centre;
  for (int y = 0; y < litMask.rows; ++y) {
    const auto* lit = litMask.ptr<std::uint8_t>(y);
    for (int x = 0; x < litMask.cols; ++x) {
      if (lit[x] == 0) continue;
      const double r =
          std::hypot((x - intrinsics.cx) / intrinsics.fx, (y - intrinsics.cy) / intrinsics.fy);
      if (r > farthest) {
        farthest = r;
        pixel = {static_cast<double>(x), static_cast<double>(y)};
      }
    }
  }
  LitFieldAngle field;
  auto ray = model.unproject(pixel);
  if (!ray) {
    // Where the rays end on the line out to that pixel (the principal point always has one).
    field.pastTheLens = true;
    double inside = 0, outside = 1;
    for (int i = 0; i < 40; ++i) {
      const double middle = (inside + outside) / 2;
      (model.unproject(centre + middle * (pixel - centre)) ? inside : outside) = middle;
    }
    ray = model.unproject(centre + inside * (pixel - centre));
  }
  field.rad = ray ? std::acos(std::clamp((*ray)[2], -1.0, 1.0)) : 0;
  return field;
}

}  // namespace surroundd::processing
