#include "tools/calibrate/guide/mat_guide_view.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

namespace surroundd::calibrate {
namespace {

// BGR; functions, because cv::Scalar's constructor is not noexcept (no static that may throw).
cv::Scalar green() { return {60, 220, 60}; }
cv::Scalar amber() { return {0, 190, 255}; }
cv::Scalar red() { return {60, 60, 240}; }
cv::Scalar white() { return {255, 255, 255}; }

void label(cv::Mat& canvas, const std::string& text, cv::Point at, const cv::Scalar& colour) {
  cv::putText(canvas, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar::all(0), 3, cv::LINE_AA);
  cv::putText(canvas, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.5, colour, 1, cv::LINE_AA);
}

// `picture` scaled into `area` of `canvas`, aspect kept; the scale used.
double place(cv::Mat& canvas, const cv::Mat& picture, const cv::Rect& area) {
  const double scale = std::min(static_cast<double>(area.width) / picture.cols,
                                static_cast<double>(area.height) / picture.rows);
  cv::Mat scaled;
  cv::resize(picture, scaled, {}, scale, scale, cv::INTER_AREA);
  scaled.copyTo(canvas(cv::Rect(area.tl(), scaled.size())));
  return scale;
}

void drawCameras(cv::Mat& canvas, const MatGuideSession& session, const cv::Rect& area) {
  const auto& cameras = session.settings().cameras;
  const int columns = 2;
  const int rows = static_cast<int>((cameras.size() + 1) / 2);
  // Cells as tall as the first lens's aspect asks, so that the pictures sit close together.
  const cv::Size lens = cameras.empty() ? cv::Size(16, 9) : cameras.front().intrinsics.imageSize;
  const int width = area.width / columns;
  const cv::Size tile(width, std::min(area.height / std::max(rows, 1),
                                      width * lens.height / std::max(lens.width, 1) + 1));
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    const cv::Rect cell(area.x + static_cast<int>(c % 2) * tile.width,
                        area.y + static_cast<int>(c / 2) * tile.height, tile.width, tile.height);
    const cv::Mat& picture = session.pictures()[c];
    std::string status = "no picture yet";
    if (!picture.empty()) {
      const double scale = place(canvas, picture, cell);
      if (const auto& result = session.result()) {
        const auto& camera = result->cameras[c];
        const cv::Scalar colour = camera.passed() ? green() : amber();
        for (const auto& sighting : camera.detection.found) {
          for (const auto& corner : sighting.pixels) {
            cv::circle(canvas, cell.tl() + cv::Point(corner * scale), 2, colour, 1, cv::LINE_AA);
          }
        }
        status = fmt::format("{}/{} boards, {}", camera.detection.found.size(),
                             camera.detection.found.size() + camera.detection.missed.size(),
                             camera.passed() ? "ok" : "FAILED");
      }
    }
    label(canvas, fmt::format("{}: {}", cameras[c].name, status), cell.tl() + cv::Point(6, 18),
          white());
  }
}

void drawTopView(cv::Mat& canvas, const MatGuideSession& session, const cv::Rect& area) {
  if (session.topView().empty()) {
    label(canvas, "top view: after the first solve", area.tl() + cv::Point(10, 24), white());
    return;
  }
  const double scale = place(canvas, session.topView(), area);
  const auto& grid = session.topViewGrid();
  const auto& mat = session.settings().mat;
  const auto at = [&](const cv::Vec3d& ground) {
    return area.tl() + cv::Point(grid.pixelOf(ground) * scale);
  };
  // Where the layout puts each board's inner-corner grid: a stitch that is right lays the
  // boards' pictures inside these outlines.
  for (const auto& board : mat.boards) {
    const auto& print = board.print;
    const double square = print.board.squareM;
    const cv::Size inner = print.board.innerCorners;
    const std::vector<cv::Point> outline{
        at(print.toVehicle({0, 0})), at(print.toVehicle({(inner.width - 1) * square, 0})),
        at(print.toVehicle({(inner.width - 1) * square, (inner.height - 1) * square})),
        at(print.toVehicle({0, (inner.height - 1) * square}))};
    cv::polylines(canvas, outline, true, white(), 1, cv::LINE_AA);
  }
  const auto& result = session.result();
  const double limit = session.settings().limits.maxSeamCm;
  for (const auto& seam : result->seams) {
    const auto& print = mat.boards[seam.board].print;
    label(canvas, fmt::format("{}|{} {:.2f} cm", seam.first, seam.second, seam.rmsCm),
          at(print.centre) + cv::Point(-60, 4), seam.rmsCm <= limit ? green() : red());
  }
  label(canvas,
        fmt::format("stitched top view; seam limit {:g} cm: {}", limit,
                    result->passed() ? "PASS" : "FAIL"),
        area.tl() + cv::Point(10, 24), result->passed() ? green() : red());
}

}  // namespace

cv::Mat matGuideFrame(const MatGuideSession& session) {
  cv::Mat canvas(kMatGuideFrameSize, CV_8UC3, cv::Scalar(17, 17, 17));
  const int half = kMatGuideFrameSize.width / 2;
  drawCameras(canvas, session, {0, 0, half, kMatGuideFrameSize.height});
  drawTopView(canvas, session, {half, 0, half, kMatGuideFrameSize.height});
  return canvas;
}

}  // namespace surroundd::calibrate
