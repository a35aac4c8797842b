#include "tools/calibrate/extrinsics/extrinsics_command.hpp"

#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "processing/calibration/extrinsic_calibration.hpp"
#include "processing/calibration/ground_marker_detection.hpp"
#include "tools/calibrate/calibration_output.hpp"
#include "tools/calibrate/extrinsics/mat_command.hpp"
#include "tools/calibrate/marker_file.hpp"
#include "tools/calibrate/residual_plot.hpp"

namespace surroundd::calibrate {
namespace {

constexpr double kRadToDeg = 180 / std::numbers::pi;

// A run of correspondences that belong together in the report and the picture: one marker's
// corners, or the listed points.
struct PointGroup {
  std::string name;
  std::size_t first = 0;
  std::size_t count = 0;
};

cv::Mat readImage(const ExtrinsicsOptions& options, cv::Size expected) {
  cv::Mat image = cv::imread(options.image.string(), cv::IMREAD_COLOR);
  if (image.empty()) {
    throw UsageError(fmt::format("--image: {}: cannot read the image (not an image, or damaged)",
                                 options.image.string()));
  }
  if (image.size() != expected) {
    throw UsageError(fmt::format(
        "--image: {} is {}x{}, but camera '{}' in {} has a {}x{} lens; calibrate the intrinsics "
        "at this resolution first",
        options.image.string(), image.cols, image.rows, options.camera, options.rig.string(),
        expected.width, expected.height));
  }
  return image;
}

void reportPose(const processing::Pose& pose, const processing::Pose& before, std::ostream& log) {
  const auto angles = processing::mountAnglesFromRotation(pose.rotation);
  const auto old = processing::mountAnglesFromRotation(before.rotation);
  cv::Vec3d turn;
  cv::Rodrigues(pose.rotation * before.rotation.t(), turn);
  log << fmt::format(
      "mount: x {:.4f} y {:.4f} z {:.4f} m, yaw {:.3f} pitch {:.3f} roll {:.3f} deg\n"
      "  change from the rig: {:.1f} cm (dx {:+.1f} dy {:+.1f} dz {:+.1f}), {:.2f} deg (yaw "
      "{:+.2f} pitch {:+.2f} roll {:+.2f})\n",
      pose.position[0], pose.position[1], pose.position[2], angles.yawDeg, angles.pitchDeg,
      angles.rollDeg, 100 * cv::norm(pose.position - before.position),
      100 * (pose.position[0] - before.position[0]), 100 * (pose.position[1] - before.position[1]),
      100 * (pose.position[2] - before.position[2]), cv::norm(turn) * kRadToDeg,
      angles.yawDeg - old.yawDeg, angles.pitchDeg - old.pitchDeg, angles.rollDeg - old.rollDeg);
}

}  // namespace

void runExtrinsics(const ExtrinsicsOptions& options, std::ostream& log) {
  if (options.mat) return runMatExtrinsics(options, log);
  const processing::CameraCalibration camera = rigCamera(options.rig, options.camera);
  const processing::MarkerLayout layout =
      options.markers ? loadMarkerFile(*options.markers) : processing::MarkerLayout{};
  const auto listed = options.points ? loadPointFile(*options.points)
                                     : std::vector<processing::PointCorrespondence>{};
  const cv::Mat image = readImage(options, camera.intrinsics.imageSize);
  cv::Mat gray;
  cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);

  // Markers first, one group each, then the listed points as one group.
  const processing::CameraModel model(camera.intrinsics);
  const auto sightings = layout.markers.empty()
                             ? std::vector<processing::MarkerSighting>{}
                             : processing::findGroundMarkers(gray, layout, model, camera.pose);
  auto points = processing::correspondencesOf(layout, sightings);
  std::vector<PointGroup> groups;
  std::vector<bool> seen(layout.markers.size(), false);
  for (const auto& sighting : sightings) {
    seen[sighting.marker] = true;
    groups.push_back({layout.markers[sighting.marker].name,
                      groups.empty() ? 0 : groups.back().first + groups.back().count,
                      sighting.pixels.size()});
  }
  if (!listed.empty()) groups.push_back({"listed points", points.size(), listed.size()});
  points.insert(points.end(), listed.begin(), listed.end());
  if (!layout.markers.empty()) {
    std::vector<std::string> missing;
    for (std::size_t m = 0; m < layout.markers.size(); ++m) {
      if (!seen[m]) missing.push_back(layout.markers[m].name);
    }
    log << fmt::format("found {} of {} markers in {}{}\n", sightings.size(), layout.markers.size(),
                       options.image.string(),
                       missing.empty() ? "" : fmt::format(" (not: {})", fmt::join(missing, ", ")));
    if (sightings.empty() && listed.empty()) {
      throw processing::CalibrationError(fmt::format(
          "none of the {} markers of {} was found in {}; is the camera and image right, and does "
          "each board's inner-corner count match the file?",
          layout.markers.size(), options.markers->string(), options.image.string()));
    }
  }

  processing::ExtrinsicSettings settings;
  settings.inlierThresholdPx = options.inlierPx;
  const auto result = processing::calibrateExtrinsics(camera.intrinsics, points, settings);

  log << "reprojection error (RMS over inliers):\n";
  std::vector<ResidualSet> sets;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const auto& group = groups[g];
    double sumSquares = 0;
    int inliers = 0;
    ResidualSet set{{}, {}, setColour(g)};
    for (std::size_t i = group.first; i < group.first + group.count; ++i) {
      const cv::Point2d residual = result.reprojected[i] - points[i].pixel;
      set.detected.push_back(points[i].pixel);
      set.residuals.push_back(residual);
      if (!result.inlier[i]) continue;
      ++inliers;
      sumSquares += residual.dot(residual);
    }
    sets.push_back(std::move(set));
    log << fmt::format(
        "  {:<24} {:7.3f} px{}\n", group.name, inliers > 0 ? std::sqrt(sumSquares / inliers) : 0.0,
        inliers < static_cast<int>(group.count)
            ? fmt::format("  ({} of {} points are outliers)", group.count - inliers, group.count)
            : "");
  }
  log << fmt::format("RMS {:.3f} px over {} of {} points\n", result.rmsPx, result.inlierCount,
                     points.size());
  reportPose(result.pose, camera.pose, log);

  const std::string comment = fmt::format(
      "Written by surround-calibrate extrinsics for camera '{}' from {}:\n"
      "{} points, RMS reprojection error {:.3f} px.",
      options.camera, options.image.string(), result.inlierCount, result.rmsPx);
  writeMountBlock(options.out, result.pose, comment);
  log << "wrote " << options.out.string() << "\n";
  if (options.residuals) {
    cv::Mat dimmed = image * 0.6;
    writeResidualPlot(*options.residuals, dimmed, sets,
                      fmt::format("camera {}: RMS {:.3f} px", options.camera, result.rmsPx));
    log << "wrote " << options.residuals->string() << "\n";
  }
  if (options.updateRig) {
    updateRigMount(options.rig, options.camera, result.pose, comment);
    log << fmt::format("updated camera '{}' in {}\n", options.camera, options.rig.string());
  }
}

}  // namespace surroundd::calibrate
