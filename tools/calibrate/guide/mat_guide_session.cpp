#include "tools/calibrate/guide/mat_guide_session.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "processing/calibration/calibration_error.hpp"

namespace surroundd::calibrate {
namespace {

// Beyond the boards and the cameras, so that the top view shows the ground between them.
constexpr double kTopViewMarginM = 1.0;

// The ground the top view shows: every board's print (its outer squares too) and every camera.
processing::GroundGrid gridAround(const MatGuideSettings& settings) {
  cv::Rect2d box;
  bool first = true;
  const auto extend = [&](double x, double y) {
    if (first) {
      box = {x, y, 0, 0};
      first = false;
      return;
    }
    const double right = std::max(box.x + box.width, x), bottom = std::max(box.y + box.height, y);
    box.x = std::min(box.x, x);
    box.y = std::min(box.y, y);
    box.width = right - box.x;
    box.height = bottom - box.y;
  };
  for (const auto& board : settings.mat.boards) {
    const auto& print = board.print;
    const double square = print.board.squareM;
    const cv::Size inner = print.board.innerCorners;
    for (const double u : {-square, inner.width * square}) {
      for (const double v : {-square, inner.height * square}) {
        const cv::Vec3d corner = print.toVehicle({u, v});
        extend(corner[0], corner[1]);
      }
    }
  }
  for (const auto& camera : settings.cameras) {
    extend(camera.pose.position[0], camera.pose.position[1]);
  }
  const double lengthM = box.width + 2 * kTopViewMarginM;  // along x: the view's height
  const double widthM = box.height + 2 * kTopViewMarginM;  // along y: the view's width
  processing::GroundGrid grid;
  grid.centre = {box.x + box.width / 2, box.y + box.height / 2};
  grid.metresPerPx = std::max(lengthM, widthM) / settings.topViewSidePx;
  grid.size = {static_cast<int>(std::ceil(widthM / grid.metresPerPx)),
               static_cast<int>(std::ceil(lengthM / grid.metresPerPx))};
  return grid;
}

}  // namespace

MatGuideSession::MatGuideSession(MatGuideSettings settings)
    : settings_(std::move(settings)),
      grid_(gridAround(settings_)),
      pictures_(settings_.cameras.size()),
      frames_(settings_.cameras.size(), 0),
      fresh_(settings_.cameras.size(), false) {
  for (const auto& board : settings_.mat.boards) {
    for (const auto& name : board.seenBy) {
      if (std::none_of(settings_.cameras.begin(), settings_.cameras.end(),
                       [&](const auto& camera) { return camera.name == name; })) {
        throw processing::CalibrationError(
            fmt::format("board '{}' is seen by camera '{}', which the rig does not have",
                        board.print.name, name));
      }
    }
  }
}

bool MatGuideSession::offer(std::size_t camera, const cv::Mat& bgr) {
  const cv::Size lens = settings_.cameras.at(camera).intrinsics.imageSize;
  if (bgr.size() != lens || bgr.type() != CV_8UC3) {
    throw std::invalid_argument(fmt::format(
        "camera '{}': a {}x{} picture for a {}x{} lens; calibrate the intrinsics at this "
        "resolution first",
        settings_.cameras[camera].name, bgr.cols, bgr.rows, lens.width, lens.height));
  }
  if (passed()) return false;  // done: the mounts are final
  bgr.copyTo(pictures_[camera]);
  ++frames_[camera];
  fresh_[camera] = true;
  if (std::find(fresh_.begin(), fresh_.end(), false) != fresh_.end()) return false;
  solve();
  return true;
}

void MatGuideSession::solve() {
  std::vector<processing::MatView> views;
  views.reserve(pictures_.size());
  for (std::size_t c = 0; c < pictures_.size(); ++c) {
    processing::MatView view{settings_.cameras[c], {}};
    cv::cvtColor(pictures_[c], view.gray, cv::COLOR_BGR2GRAY);
    views.push_back(std::move(view));
  }
  result_ = processing::calibrateFromMat(settings_.mat, views, settings_.limits,
                                         settings_.detection, settings_.solve);
  ++solves_;
  std::fill(fresh_.begin(), fresh_.end(), false);
  std::vector<processing::CameraCalibration> solved = settings_.cameras;
  for (std::size_t c = 0; c < solved.size(); ++c) {
    if (const auto& s = result_->cameras[c].solve) solved[c].pose = s->pose;
  }
  topView_ = processing::stitchedTopView(solved, pictures_, grid_);
}

std::vector<std::string> MatGuideSession::hints() const {
  if (passed()) return {"every camera and seam passed: the mounts are final"};
  std::vector<std::string> hints;
  for (std::size_t c = 0; c < pictures_.size(); ++c) {
    if (frames_[c] == 0) {
      hints.push_back(fmt::format("waiting for camera {}'s picture", settings_.cameras[c].name));
    }
  }
  if (!result_) return hints;
  for (const auto& camera : result_->cameras) {
    for (const auto& problem : camera.problems) {
      hints.push_back(fmt::format("camera {}: {}", camera.camera, problem));
    }
  }
  for (const auto& problem : result_->problems) hints.push_back(problem);
  hints.emplace_back(
      "check that every board lies where the mat's layout says, at its size, and that each "
      "camera sees its boards whole; the next pictures solve again");
  return hints;
}

}  // namespace surroundd::calibrate
