#include "tools/synth/calibration_mat.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "tools/synth/calibration_scenes.hpp"

namespace surroundd::synth {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180;
// Mat boards are found in a top view of the ground
// (processing/calibration/mat_board_detection.hpp), which undoes the shear of a slanted view; the
// squares must still be large enough in the picture for cornerSubPix there.
constexpr ViewFit kMatFit{6, 4, false};

// The optical axis's heading on the ground, radians from +x towards +y.
double headingOf(const processing::CameraCalibration& camera) {
  const cv::Vec3d axis = camera.pose.rotation * cv::Vec3d(0, 0, 1);
  return std::atan2(axis[1], axis[0]);
}

double printRadius(const processing::Checkerboard& board) {
  return std::hypot(board.innerCorners.width + 3, board.innerCorners.height + 3) * board.squareM /
         2;
}

struct Footprint {
  cv::Point2d low, high;
};

Footprint cameraBox(std::span<const processing::CameraCalibration> cameras) {
  Footprint box{{1e9, 1e9}, {-1e9, -1e9}};
  for (const auto& camera : cameras) {
    box.low = {std::min(box.low.x, camera.pose.position[0]),
               std::min(box.low.y, camera.pose.position[1])};
    box.high = {std::max(box.high.x, camera.pose.position[0]),
                std::max(box.high.y, camera.pose.position[1])};
  }
  return box;
}

// The nearest place along `heading` from `from` where every camera in `viewers` sees the print
// whole, clear of the car's box and of the boards already laid.
std::optional<processing::GroundMarker> placeBoard(
    processing::GroundMarker print, cv::Point2d from, double heading,
    std::span<const processing::CameraCalibration* const> viewers, const Footprint& car,
    const processing::MatLayout& laid) {
  const double radius = printRadius(print.board);
  const cv::Point2d direction(std::cos(heading), std::sin(heading));
  const cv::Point2d across(-direction.y, direction.x);
  // Outwards in 5 cm steps from 0.5 m to 10 m.
  for (int step = 10; step < 200; ++step) {
    const double distance = step * 0.05;
    for (const double sideways : {0.0, 0.2, -0.2, 0.4, -0.4}) {
      // Square to the car first, then turned to face along the heading.
      for (const double yawDeg : {0.0, 90.0, heading / kDegToRad - 90}) {
        // To the centimetre, as a mat's places are measured.
        const cv::Point2d exact = from + distance * direction + sideways * distance * across;
        const cv::Point2d centre(std::round(exact.x * 100) / 100, std::round(exact.y * 100) / 100);
        const bool onCar = centre.x + radius > car.low.x && centre.x - radius < car.high.x &&
                           centre.y + radius > car.low.y && centre.y - radius < car.high.y;
        if (onCar) continue;
        const bool apart = std::all_of(laid.boards.begin(), laid.boards.end(), [&](auto& other) {
          const cv::Vec3d gap = other.print.centre - cv::Vec3d(centre.x, centre.y, 0);
          return cv::norm(gap) > printRadius(other.print.board) + radius + 0.8;
        });
        if (!apart) continue;
        print.centre = {centre.x, centre.y, 0};
        print.yawDeg = yawDeg;
        const bool seen = std::all_of(viewers.begin(), viewers.end(), [&](const auto* camera) {
          return markerFitsView(*camera, print, 0, kMatFit);
        });
        if (seen) return print;
      }
    }
  }
  return std::nullopt;
}

}  // namespace

processing::MatLayout groundMatAroundRig(std::span<const processing::CameraCalibration> cameras,
                                         const GroundMatRequest& request) {
  processing::MatLayout mat;
  const Footprint car = cameraBox(cameras);
  const auto lay = [&](const std::string& name,
                       std::span<const processing::CameraCalibration* const> viewers,
                       cv::Point2d from, double heading) {
    processing::GroundMarker print;
    print.name = name;
    print.board = request.board;
    const auto placed = placeBoard(print, from, heading, viewers, car, mat);
    if (!placed) {
      throw std::runtime_error(
          fmt::format("no place for a {}x{} board of {:g} m squares that {} "
                      "see whole",
                      request.board.innerCorners.width, request.board.innerCorners.height,
                      request.board.squareM, name));
    }
    processing::MatBoard board{*placed, {}};
    for (const auto* camera : viewers) board.seenBy.push_back(camera->name);
    mat.boards.push_back(std::move(board));
  };
  for (std::size_t i = 0; i < cameras.size() && cameras.size() > 1; ++i) {
    const auto& a = cameras[i];
    const auto& b = cameras[(i + 1) % cameras.size()];
    const double ha = headingOf(a), hb = headingOf(b);
    // The bisector of the two headings, on the side of their smaller angle.
    const double heading = std::atan2(std::sin(ha) + std::sin(hb), std::cos(ha) + std::cos(hb));
    const cv::Point2d from((a.pose.position[0] + b.pose.position[0]) / 2,
                           (a.pose.position[1] + b.pose.position[1]) / 2);
    const std::array<const processing::CameraCalibration*, 2> viewers{&a, &b};
    lay(fmt::format("{}_{}", a.name, b.name), viewers, from, heading);
  }
  for (const auto& name : request.boardAhead) {
    const auto camera =
        std::find_if(cameras.begin(), cameras.end(), [&](const auto& c) { return c.name == name; });
    if (camera == cameras.end()) {
      throw std::runtime_error(fmt::format("no camera '{}' to lay a board ahead of", name));
    }
    const std::array<const processing::CameraCalibration*, 1> viewers{&*camera};
    lay(fmt::format("{}_ahead", name), viewers,
        {camera->pose.position[0], camera->pose.position[1]}, headingOf(*camera));
  }
  return mat;
}

processing::MarkerLayout printsOf(const processing::MatLayout& mat) {
  processing::MarkerLayout layout;
  for (const auto& board : mat.boards) layout.markers.push_back(board.print);
  return layout;
}

std::string matYaml(const processing::MatLayout& mat, std::string_view comment) {
  YAML::Emitter out;
  out.SetDoublePrecision(12);
  if (!comment.empty()) out << YAML::Comment(std::string(comment));
  out << YAML::BeginMap << YAML::Key << "boards" << YAML::Value << YAML::BeginSeq;
  for (const auto& board : mat.boards) {
    const auto& print = board.print;
    out << YAML::BeginMap << YAML::Key << "name" << YAML::Value << print.name;
    out << YAML::Key << "inner_corners" << YAML::Value << YAML::Flow << YAML::BeginSeq
        << print.board.innerCorners.width << print.board.innerCorners.height << YAML::EndSeq;
    out << YAML::Key << "square_m" << YAML::Value << print.board.squareM;
    out << YAML::Key << "x_m" << YAML::Value << print.centre[0];
    out << YAML::Key << "y_m" << YAML::Value << print.centre[1];
    if (print.centre[2] != 0) out << YAML::Key << "z_m" << YAML::Value << print.centre[2];
    out << YAML::Key << "yaw_deg" << YAML::Value << print.yawDeg;
    out << YAML::Key << "seen_by" << YAML::Value << YAML::Flow << board.seenBy;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

processing::Pose mountMeasuredByHand(const processing::Pose& truth) {
  processing::Pose pose = truth;
  pose.position += cv::Vec3d(0.04, -0.03, 0.05);
  const auto angles = processing::mountAnglesFromRotation(truth.rotation);
  pose.rotation = processing::rotationFromMountAngles(
      {angles.yawDeg + 2.0, angles.pitchDeg - 1.5, angles.rollDeg + 1.0});
  return pose;
}

}  // namespace surroundd::synth
