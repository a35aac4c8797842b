// The fisheye solve's covariance (see intrinsic_calibration.hpp, fisheyeUncertainty).

#include <cmath>

#include <opencv2/calib3d.hpp>

#include "processing/calibration/intrinsic_calibration.hpp"

namespace surroundd::processing {
namespace {

// cv::fisheye::projectPoints' Jacobian columns: f (2), c (2), k (4), rvec (3), tvec (3), alpha.
constexpr int kLensParameters = 8;
constexpr int kPoseColumn = 8;
constexpr int kPoseParameters = 6;

}  // namespace

IntrinsicsUncertainty fisheyeUncertainty(const Intrinsics& lens,
                                         std::span<const std::vector<cv::Point3f>> grids,
                                         std::span<const std::vector<cv::Point2f>> corners,
                                         std::span<const cv::Vec3d> rvecs,
                                         std::span<const cv::Vec3d> tvecs) {
  const cv::Matx33d k(lens.fx, 0, lens.cx, 0, lens.fy, lens.cy, 0, 0, 1);
  const cv::Vec4d d(lens.distortion[0], lens.distortion[1], lens.distortion[2], lens.distortion[3]);
  // Normal equations with the poses eliminated: S = A - sum_v B_v C_v^-1 B_v^T, where A is the
  // lens block, C_v a view's pose block and B_v their cross terms.
  cv::Mat schur = cv::Mat::zeros(kLensParameters, kLensParameters, CV_64F);
  double sumSquares = 0;
  int observations = 0;
  for (std::size_t v = 0; v < grids.size(); ++v) {
    std::vector<cv::Point2d> projected;
    cv::Mat jacobian;
    std::vector<cv::Point3d> points(grids[v].begin(), grids[v].end());
    cv::fisheye::projectPoints(points, projected, rvecs[v], tvecs[v], k, d, 0, jacobian);
    for (std::size_t i = 0; i < projected.size(); ++i) {
      const cv::Point2d r = projected[i] - cv::Point2d(corners[v][i]);
      sumSquares += r.dot(r);
    }
    observations += 2 * static_cast<int>(projected.size());
    const cv::Mat lensColumns = jacobian.colRange(0, kLensParameters);
    const cv::Mat poseColumns = jacobian.colRange(kPoseColumn, kPoseColumn + kPoseParameters);
    const cv::Mat cross = lensColumns.t() * poseColumns;
    const cv::Mat poseBlock = poseColumns.t() * poseColumns;
    schur += lensColumns.t() * lensColumns - cross * poseBlock.inv(cv::DECOMP_SVD) * cross.t();
  }
  const int freedom =
      observations - kLensParameters - kPoseParameters * static_cast<int>(grids.size());
  IntrinsicsUncertainty u;
  if (freedom <= 0) return u;
  const cv::Mat covariance = schur.inv(cv::DECOMP_SVD) * (sumSquares / freedom);
  const auto deviation = [&](int i) {
    return std::sqrt(std::max(0.0, covariance.at<double>(i, i)));
  };
  u.fx = deviation(0), u.fy = deviation(1), u.cx = deviation(2), u.cy = deviation(3);
  for (int i = 0; i < 4; ++i) u.distortion[static_cast<std::size_t>(i)] = deviation(4 + i);
  return u;
}

}  // namespace surroundd::processing
