#include "tools/calibrate/marker_file.hpp"

#include <cmath>
#include <set>

#include <fmt/format.h>

#include "daemon/config/yaml_reader.hpp"

namespace surroundd::calibrate {
namespace {

using daemon::NumberRange;
using daemon::YamlObject;
using processing::MarkerKind;

constexpr NumberRange kMetres{-100.0, 100.0, false, "metres, vehicle frame"};
constexpr NumberRange kSize{0.0, 10.0, true, "metres"};

// `symmetricAllowed`: boards whose two ends look alike are fine (the mat's boards are oriented
// with the nominal mount's help; lone ground markers are not).
std::optional<cv::Size> readInnerCorners(YamlObject& entry, bool symmetricAllowed) {
  const auto counts = entry.numbers("inner_corners", {2});
  if (!counts) return std::nullopt;
  const double cols = (*counts)[0], rows = (*counts)[1];
  const bool whole = cols == std::floor(cols) && rows == std::floor(rows);
  if (!whole || cols < 2 || rows < 2 || cols > 64 || rows > 64 ||
      (!symmetricAllowed && static_cast<int>(cols + rows) % 2 == 0)) {
    entry.error("inner_corners",
                fmt::format("expected [columns, rows] of inner corners, each 2 to 64{} (e.g. "
                            "[5, 4]), got [{:g}, {:g}]",
                            symmetricAllowed ? ""
                                             : ", one odd and one even so that the board's two "
                                               "ends differ",
                            cols, rows));
    return std::nullopt;
  }
  return cv::Size(static_cast<int>(cols), static_cast<int>(rows));
}

// Centre and yaw on the ground, shared by markers and mat boards.
void readPlacement(YamlObject& entry, processing::GroundMarker& marker) {
  marker.centre = {entry.requiredNumber("x_m", kMetres).value_or(0.0),
                   entry.requiredNumber("y_m", kMetres).value_or(0.0),
                   entry.number("z_m", 0.0, kMetres)};
  marker.yawDeg = entry.number("yaw_deg", 0.0, {-360.0, 360.0, false, "degrees"});
}

processing::GroundMarker readMarker(YamlObject& entry) {
  processing::GroundMarker marker;
  marker.name = entry.requiredString("name").value_or("");
  marker.kind =
      entry.choice("type", MarkerKind::kCheckerboard,
                   {{"checkerboard", MarkerKind::kCheckerboard}, {"aruco", MarkerKind::kAruco}});
  if (marker.kind == MarkerKind::kCheckerboard) {
    marker.board.innerCorners = readInnerCorners(entry, false).value_or(cv::Size(5, 4));
    marker.board.squareM = entry.requiredNumber("square_m", kSize).value_or(0.1);
  } else {
    marker.arucoId = entry.requiredInteger("id", 0, 4095).value_or(0);
    marker.arucoSideM = entry.requiredNumber("side_m", kSize).value_or(0.1);
  }
  readPlacement(entry, marker);
  entry.finish();
  return marker;
}

processing::MatBoard readMatBoard(YamlObject& entry) {
  processing::MatBoard board;
  auto& print = board.print;
  print.name = entry.requiredString("name").value_or("");
  print.board.innerCorners = readInnerCorners(entry, true).value_or(cv::Size(5, 4));
  if (!entry.has("inner_corners")) entry.errorHere("missing key 'inner_corners' ([columns, rows])");
  print.board.squareM = entry.requiredNumber("square_m", kSize).value_or(0.1);
  readPlacement(entry, print);
  if (!entry.has("seen_by")) {
    entry.errorHere("missing key 'seen_by' (the one or two cameras that see the board)");
  }
  board.seenBy = entry.strings("seen_by", 1, 2).value_or(std::vector<std::string>{});
  if (board.seenBy.size() == 2 && board.seenBy[0] == board.seenBy[1]) {
    entry.error("seen_by", fmt::format("names camera '{}' twice", board.seenBy[0]));
  }
  entry.finish();
  return board;
}

// Parses `file` and reads its root with `read`; throws ConfigError listing every problem.
template <typename Read>
auto readYamlFile(const std::filesystem::path& file, Read read) {
  daemon::Diagnostics diagnostics;
  YamlObject root(daemon::parseYamlFile(file), "", file, diagnostics);
  auto result = read(root);
  root.finish();
  diagnostics.throwIfAny();
  return result;
}

}  // namespace

processing::MarkerLayout loadMarkerFile(const std::filesystem::path& file) {
  return readYamlFile(file, [](YamlObject& root) {
    processing::MarkerLayout layout;
    const std::string dictionary = root.string("aruco_dictionary", "4x4_50");
    if (const auto id = processing::arucoDictionaryByName(dictionary)) {
      layout.arucoDictionary = *id;
    } else {
      root.error("aruco_dictionary", fmt::format("expected one of {}, got '{}'",
                                                 processing::arucoDictionaryNames(), dictionary));
    }
    std::set<std::string, std::less<>> names;
    std::set<int> arucoIds;
    for (auto& entry : root.objectList("markers", 1, 256)) {
      auto marker = readMarker(entry);
      if (!marker.name.empty() && !names.insert(marker.name).second) {
        entry.error("name", fmt::format("duplicate marker name '{}'", marker.name));
      }
      if (marker.kind == MarkerKind::kAruco && !arucoIds.insert(marker.arucoId).second) {
        entry.error("id", fmt::format("duplicate ArUco id {} (a marker names itself by its id)",
                                      marker.arucoId));
      }
      layout.markers.push_back(std::move(marker));
    }
    return layout;
  });
}

processing::MatLayout loadMatFile(const std::filesystem::path& file) {
  return readYamlFile(file, [](YamlObject& root) {
    processing::MatLayout mat;
    std::set<std::string, std::less<>> names;
    for (auto& entry : root.objectList("boards", 1, 64)) {
      auto board = readMatBoard(entry);
      if (!board.print.name.empty() && !names.insert(board.print.name).second) {
        entry.error("name", fmt::format("duplicate board name '{}'", board.print.name));
      }
      mat.boards.push_back(std::move(board));
    }
    return mat;
  });
}

std::vector<processing::PointCorrespondence> loadPointFile(const std::filesystem::path& file) {
  return readYamlFile(file, [](YamlObject& root) {
    std::vector<processing::PointCorrespondence> points;
    const NumberRange pixels{-1e5, 1e5, false, "pixels"};
    for (auto& entry : root.objectList("points", 1, 100000)) {
      processing::PointCorrespondence point;
      point.label = fmt::format("point '{}'", entry.requiredString("name").value_or(""));
      point.vehicle = {entry.requiredNumber("x_m", kMetres).value_or(0.0),
                       entry.requiredNumber("y_m", kMetres).value_or(0.0),
                       entry.number("z_m", 0.0, kMetres)};
      point.pixel = {entry.requiredNumber("u_px", pixels).value_or(0.0),
                     entry.requiredNumber("v_px", pixels).value_or(0.0)};
      entry.finish();
      points.push_back(std::move(point));
    }
    return points;
  });
}

}  // namespace surroundd::calibrate
