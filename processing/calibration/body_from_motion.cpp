#include "processing/calibration/body_from_motion.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "processing/lens/camera_model.hpp"

namespace surroundd::processing {
namespace {

// Per pixel inside the lens's field: 255 in `down` where its ray points below the horizon, in
// `up` where above; 0 in both outside the field.
void raysByHorizon(const CameraCalibration& camera, cv::Mat& down, cv::Mat& up) {
  const CameraModel model(camera.intrinsics);
  const cv::Size size = camera.intrinsics.imageSize;
  down.create(size, CV_8U);
  up.create(size, CV_8U);
  for (int y = 0; y < size.height; ++y) {
    auto* below = down.ptr<std::uint8_t>(y);
    auto* above = up.ptr<std::uint8_t>(y);
    for (int x = 0; x < size.width; ++x) {
      const auto ray = model.unproject({static_cast<double>(x), static_cast<double>(y)});
      const bool downward = ray && (camera.pose.rotation * *ray)[2] < 0;
      below[x] = downward ? 255 : 0;
      above[x] = ray && !downward ? 255 : 0;
    }
  }
}

// The picture's border and the pixels next to the lens's field's edge.
cv::Mat edgeOf(const cv::Mat& down, const cv::Mat& up) {
  cv::Mat outside = ~(down | up);
  cv::dilate(outside, outside, cv::Mat());
  cv::Mat edge = outside.clone();
  cv::rectangle(edge, cv::Rect({0, 0}, edge.size()), cv::Scalar(255), 1);
  return edge;
}

// Blur against noise and compression: a few pixels, growing with the picture.
int blurSide(cv::Size size) { return std::max(3, (size.width / 320) | 1); }

}  // namespace

BodyFromMotion::BodyFromMotion(const CameraCalibration& camera, BodyFromMotionSettings settings)
    : settings_(settings),
      changed_(camera.intrinsics.imageSize, CV_16U, cv::Scalar(0)),
      edged_(camera.intrinsics.imageSize, CV_16U, cv::Scalar(0)),
      xx_(camera.intrinsics.imageSize, CV_32F, cv::Scalar(0)),
      yy_(camera.intrinsics.imageSize, CV_32F, cv::Scalar(0)),
      xy_(camera.intrinsics.imageSize, CV_32F, cv::Scalar(0)) {
  raysByHorizon(camera, candidates_, sky_);
  edge_ = edgeOf(candidates_, sky_);
}

void BodyFromMotion::add(const cv::Mat& picture) {
  if (picture.size() != candidates_.size() || picture.type() != CV_8UC3) {
    throw std::invalid_argument(fmt::format(
        "expected an 8-bit BGR picture of {}x{} (the lens's size), got {}x{} of type {}",
        candidates_.cols, candidates_.rows, picture.cols, picture.rows, picture.type()));
  }
  cv::cvtColor(picture, grey_, cv::COLOR_BGR2GRAY);
  const int side = blurSide(picture.size());
  cv::GaussianBlur(grey_, blurred_, {side, side}, 0);
  cv::Mat current;
  blurred_.convertTo(current, CV_32F);
  if (std::ssize(recent_) == settings_.span) {
    const cv::Mat& before = recent_.front();
    // The camera's auto exposure changes every pixel alike: matched before comparing.
    const double then = cv::mean(before, candidates_)[0];
    const double now = cv::mean(current, candidates_)[0];
    cv::Mat matched = now > 1 ? cv::Mat(current * (then / now)) : current;
    cv::absdiff(matched, before, change_);
    const cv::Mat moved = change_ > settings_.changeLevels;
    cv::add(changed_, cv::Scalar(1), changed_, moved);
    ++pairs_;
    recent_.erase(recent_.begin());
  }
  recent_.push_back(current);
  // The edges' orientations, for staticEdges().
  cv::Sobel(current, gx_, CV_32F, 1, 0);
  cv::Sobel(current, gy_, CV_32F, 0, 1);
  cv::accumulateProduct(gx_, gx_, xx_);
  cv::accumulateProduct(gy_, gy_, yy_);
  cv::accumulateProduct(gx_, gy_, xy_);
  cv::magnitude(gx_, gy_, change_);
  cv::add(edged_, cv::Scalar(1), edged_, change_ > settings_.edgeStrength);
  ++pictures_;
}

cv::Mat BodyFromMotion::staticEdges() const {
  // Coherence of the summed structure tensor: 1 where every picture had an edge of one
  // orientation, near 0 where orientations varied (texture sliding past).
  cv::Mat difference = xx_ - yy_;
  cv::Mat coherence;
  cv::magnitude(difference, 2 * xy_, coherence);
  cv::divide(coherence, xx_ + yy_ + 1e-6, coherence);
  return (coherence >= settings_.edgeCoherence) & (edged_ >= settings_.edgePresence * pictures_) &
         candidates_;
}

double BodyFromMotion::movingShare() const {
  if (pairs_ == 0) return 0;
  const cv::Mat moving = changed_ > settings_.stillShare * pairs_;
  const double candidates = cv::countNonZero(candidates_);
  return candidates > 0 ? cv::countNonZero(moving & candidates_) / candidates : 0;
}

cv::Mat BodyFromMotion::mask() const {
  const cv::Size size = candidates_.size();
  // The scene: what is reached from the rays above the horizon through pixels that are not still.
  // A body that mirrors the moving sky (a glossy roof) is not still either, but its edge, which
  // does not move, keeps the scene out of it.
  const cv::Mat notStill = (changed_ > settings_.stillShare * pairs_) & candidates_;
  const cv::Mat passable = (notStill & ~staticEdges()) | sky_;
  cv::Mat labels;
  const int count = cv::connectedComponents(passable, labels, 4, CV_32S);
  std::vector<char> scene(static_cast<std::size_t>(count), 0);
  for (int y = 0; y < size.height; ++y) {
    const auto* label = labels.ptr<int>(y);
    const auto* sky = sky_.ptr<std::uint8_t>(y);
    for (int x = 0; x < size.width; ++x) {
      if (sky[x] != 0) scene[static_cast<std::size_t>(label[x])] = 1;
    }
  }
  cv::Mat body = candidates_.clone();
  for (int y = 0; y < size.height; ++y) {
    const auto* label = labels.ptr<int>(y);
    auto* out = body.ptr<std::uint8_t>(y);
    for (int x = 0; x < size.width; ++x) {
      if (label[x] != 0 && scene[static_cast<std::size_t>(label[x])] != 0) out[x] = 0;
    }
  }
  // What is left of the body: regions that reach the picture's or the lens's edge (a camera sees
  // its own car from there in), large enough; ground with no texture that the scene surrounds
  // goes.
  cv::Mat regions, stats, centres;
  const int regionCount = cv::connectedComponentsWithStats(body, regions, stats, centres, 8);
  std::vector<char> keep(static_cast<std::size_t>(regionCount), 0);
  const double minArea = settings_.minRegionShare * size.area();
  for (int y = 0; y < size.height; ++y) {
    const auto* region = regions.ptr<int>(y);
    const auto* edge = edge_.ptr<std::uint8_t>(y);
    for (int x = 0; x < size.width; ++x) {
      if (region[x] != 0 && edge[x] != 0 && stats.at<int>(region[x], cv::CC_STAT_AREA) >= minArea) {
        keep[static_cast<std::size_t>(region[x])] = 1;
      }
    }
  }
  for (int y = 0; y < size.height; ++y) {
    const auto* region = regions.ptr<int>(y);
    auto* out = body.ptr<std::uint8_t>(y);
    for (int x = 0; x < size.width; ++x) {
      if (keep[static_cast<std::size_t>(region[x])] == 0) out[x] = 0;
    }
  }
  // The outline smoothed: a pixel's verdict is noisy where the ground meets the body.
  const cv::Mat round = cv::getStructuringElement(cv::MORPH_ELLIPSE, {5, 5});
  cv::morphologyEx(body, body, cv::MORPH_CLOSE, round);
  cv::morphologyEx(body, body, cv::MORPH_OPEN, round);
  return body & candidates_;
}

std::vector<std::vector<cv::Point>> maskOutlines(const cv::Mat& mask, double tolerancePx) {
  std::vector<std::vector<cv::Point>> outlines;
  cv::findContours(mask.clone(), outlines, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  std::vector<std::vector<cv::Point>> polygons;
  for (const auto& outline : outlines) {
    std::vector<cv::Point> polygon;
    cv::approxPolyDP(outline, polygon, tolerancePx, true);
    if (polygon.size() >= 3) polygons.push_back(std::move(polygon));
  }
  return polygons;
}

}  // namespace surroundd::processing
