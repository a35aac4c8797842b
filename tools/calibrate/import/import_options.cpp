#include "tools/calibrate/import/import_options.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {

const std::string_view kImportUsage =
    R"(usage: surround-calibrate import (--camera NAME=FILE[,FILE...]... | --pjlab DIR | --pjlab-yaml FILE)
                              --out RIG [frame options] [lens options] [--images DIR]

Writes a rig file (daemon/config/rig_yaml.hpp) from a calibration made by another tool, in the project's
vehicle frame: origin on the ground under the vehicle centre, x forward, y left, z up, metres;
camera frame OpenCV (x right, y down, z forward); mount angles as in processing/rig.hpp.

Input (one kind):
  --camera NAME=FILE[,FILE...]  one camera's files, repeatable (NAME: front, right, back, left or
                             any other name). A .txt file is OCamCalib's calib_results.txt (lens
                             only); any other (.yml .yaml .json .xml) is an OpenCV FileStorage file
                             searched, nested maps included, for the first of these keys:
                               camera matrix: camera_matrix cameraMatrix K cam_K intrinsic_matrix
                                 (3x3, or [fx, fy, cx, cy])
                               distortion: dist_coeffs distCoeffs distortion_coefficients D
                                 cam_dist dist (pinhole k1 k2 p1 p2 [k3]; fisheye k1..k4)
                               lens model: distortion_model camera_model lens_model
                                 (fisheye|equidistant|kannala_brandt, pinhole|plumb_bob|radtan)
                               image size: image_width + image_height, img_dist_w + img_dist_h,
                                 image_size, imageSize or resolution [w, h]
                               pose, one of: rvec + tvec; R (3x3) + t; a 4x4 (or 3x4) matrix
                                 T sensor_calib T_cam_from_G extrinsic transform; or a ground
                                 homography: H / homography (canvas to picture, see
                                 --canvas-scale) or project_matrix (picture to canvas), through
                                 K, or through K' = K with fx, fy times scale_xy and cx, cy plus
                                 shift_xy where the file has them
                             Matrices may be opencv-matrix nodes, {rows, cols, data} maps, or
                             plain (nested) lists. The first file that has a key wins.
  --pjlab DIR                the JSON layout of PJLab SensorsCalibration's surround samples:
                             DIR/intrinsic/<Cam>.json (cam_K, cam_dist, img_dist_w/h) and
                             DIR/extrinsic/<Cam>.json (sensor_calib, P_cam = T * P_source), one
                             camera per intrinsic file (Front.json becomes camera 'front')
  --pjlab-yaml FILE          a calibration.yaml of that layout in plain YAML: image_size [w, h],
                             cameras: {<name>: {K: [fx, fy, cx, cy], D: [...], T_cam_from_G: 4x4}}

The source frame (nothing is guessed; the rig is only right when these are):
  --axes X,Y,Z               where the source frame's x, y and z axes point on the vehicle, each
                             one of forward, back, left, right, up, down (default forward,left,up).
                             E.g. a top-down view with x right, y towards the rear, z down:
                             right,back,down. Must be right-handed.
  --unit-m U                 metres per source length unit (default 1; 0.1 for decimetres)
  --ground-z Z | NAME=Z,...  the ground's coordinate on the source's vertical axis, in source
                             units (default 0); per camera as front=6.07,left=6.25,... where each
                             camera's pose has its own ground (the others keep 0, or a plain Z
                             given before)
  --origin-centre            move the origin to the centre of the bounding box of the camera
                             positions, on the ground (x and y only); default: the source origin
                             (dropped to the ground) stays the vehicle origin
  --offset-m X,Y,Z           then add this to every camera position (vehicle frame, metres)
  --pose-direction DIR       to-camera (default): a pose maps source points into the camera,
                             P_cam = R * P_source + t, as solvePnP's rvec/tvec; to-source: the
                             pose is the camera's in the source frame, P_source = R * P_cam + t
  --canvas-scale S           with a homography: source units per canvas pixel. H maps canvas
                             pixels on the ground to pixels of the camera's undistorted image
                             (through its K): [u v 1]' ~ H [cu cv 1]', where canvas pixel (cu, cv)
                             is the source point ((cu - ou) * S, (cv - ov) * S, ground-z): canvas
                             columns along source x, rows along source y, so the source z axis
                             must be vertical
  --canvas-origin OU,OV      the canvas pixel of the source origin (default 0,0)
  --canvas-strips WxH        the canvas is W x H pixels and each camera's homography targets a
                             strip of its own, turned onto the canvas with its top edge outward
                             on the camera's side (from its name: front at the top as it is,
                             right turned 90 degrees clockwise, back 180, left 90 counter-
                             clockwise), as surround-view-system-introduction's files do: e.g.
                             --lens fisheye --canvas-strips 1200x1600 --canvas-scale 1
                             --canvas-origin 600,800 --axes right,back,down --unit-m 0.01

Lens:
  --lens MODEL               pinhole, fisheye or ocam; default: the file's model key, else pinhole
                             when the distortion has 5 or only zero coefficients (4 non-zero ones
                             are ambiguous and need --lens). ocam with --pjlab: cam_K holds
                             [[c, d, xc], [e, 1, yc]] and cam_dist OCamCalib's invpol
  --image-size WxH           when the files do not say (default: the camera's picture in --images)
  --field-of-view-deg D      fisheye, ocam: the lens's full field (default: as far as the
                             camera's picture in --images is lit, else as far as the image's
                             corners; at most 200, and never past where the polynomial stops
                             increasing)

Output:
  --out RIG                  the rig file (written beside and renamed); its header comment names
                             the inputs and these options
  --images DIR               a still picture per camera in DIR, found by the camera's source name
                             (Front.png, front.jpg, ...): written as each camera's source (loop)
                             with a path relative to the rig file

Cameras are written in the order front, right, back, left, then the others; roles as a rig
file's default (looking along the vehicle: source; sideways: target).
)";

namespace {

std::string lower(std::string_view text) {
  std::string out(text);
  std::ranges::transform(out, out.begin(), [](unsigned char c) { return std::tolower(c); });
  return out;
}

std::vector<std::string_view> split(std::string_view text, char separator) {
  std::vector<std::string_view> parts;
  for (std::size_t start = 0;;) {
    const auto end = text.find(separator, start);
    parts.push_back(text.substr(start, end - start));
    if (end == std::string_view::npos) return parts;
    start = end + 1;
  }
}

std::vector<double> parseNumbers(std::string_view option, std::string_view text, std::size_t count,
                                 std::string_view expected) {
  const auto parts = split(text, ',');
  if (parts.size() != count) {
    throw UsageError(fmt::format("{}: expected {}, got '{}'", option, expected, text));
  }
  std::vector<double> values;
  for (const auto part : parts) values.push_back(parseDouble(option, part, -1e6, 1e6, expected));
  return values;
}

cv::Vec3d direction(std::string_view option, std::string_view word, std::string_view all) {
  static const std::map<std::string, cv::Vec3d, std::less<>> kDirections{
      {"forward", {1, 0, 0}}, {"back", {-1, 0, 0}}, {"left", {0, 1, 0}},
      {"right", {0, -1, 0}},  {"up", {0, 0, 1}},    {"down", {0, 0, -1}}};
  const auto it = kDirections.find(lower(word));
  if (it == kDirections.end()) {
    throw UsageError(fmt::format(
        "{}: expected three of forward, back, left, right, up, down (e.g. right,back,down), got "
        "'{}'",
        option, all));
  }
  return it->second;
}

cv::Matx33d parseAxes(std::string_view text) {
  const auto parts = split(text, ',');
  if (parts.size() != 3) {
    throw UsageError(
        fmt::format("--axes: expected X,Y,Z directions (e.g. right,back,down), got '{}'", text));
  }
  cv::Matx33d axes;
  for (int c = 0; c < 3; ++c) {
    const auto v = direction("--axes", parts[static_cast<std::size_t>(c)], text);
    for (int r = 0; r < 3; ++r) axes(r, c) = v[r];
  }
  const double det = cv::determinant(axes);
  if (std::abs(det) < 0.5) {
    throw UsageError(fmt::format("--axes: the three axes must be perpendicular, got '{}'", text));
  }
  if (det < 0) {
    throw UsageError(fmt::format(
        "--axes: '{}' is a left-handed (mirrored) frame; a calibration's frame is right-handed, "
        "so one of the directions is wrong",
        text));
  }
  return axes;
}

cv::Size parseSize(std::string_view option, std::string_view text) {
  const auto x = text.find('x');
  int width = 0, height = 0;
  const auto w = text.substr(0, x == std::string_view::npos ? 0 : x);
  const auto h = x == std::string_view::npos ? std::string_view{} : text.substr(x + 1);
  const auto a = std::from_chars(w.data(), w.data() + w.size(), width);
  const auto b = std::from_chars(h.data(), h.data() + h.size(), height);
  if (w.empty() || h.empty() || a.ec != std::errc() || a.ptr != w.data() + w.size() ||
      b.ec != std::errc() || b.ptr != h.data() + h.size() || width < 16 || height < 16 ||
      width > 16384 || height > 16384) {
    throw UsageError(
        fmt::format("{}: expected WxH in pixels (e.g. 1280x720), got '{}'", option, text));
  }
  return {width, height};
}

void parseCamera(ImportOptions& o, std::string_view text) {
  const auto equals = text.find('=');
  if (equals == std::string_view::npos || equals == 0 || equals + 1 == text.size()) {
    throw UsageError(fmt::format(
        "--camera: expected NAME=FILE[,FILE...] (e.g. front=front.yml), got '{}'", text));
  }
  const std::string name = lower(text.substr(0, equals));
  if (o.cameraFiles.contains(name)) {
    throw UsageError(fmt::format("--camera: camera '{}' is given twice", name));
  }
  auto& files = o.cameraFiles[name];
  for (const auto file : split(text.substr(equals + 1), ',')) {
    if (file.empty()) throw UsageError(fmt::format("--camera: an empty file name in '{}'", text));
    files.emplace_back(std::string(file));
  }
}

void parseGround(ImportOptions& o, std::string_view text) {
  if (text.find('=') == std::string_view::npos) {
    o.groundZ = parseDouble("--ground-z", text, -1e6, 1e6, "a number, or NAME=Z,...");
    return;
  }
  for (const auto part : split(text, ',')) {
    const auto equals = part.find('=');
    if (equals == std::string_view::npos || equals == 0) {
      throw UsageError(fmt::format("--ground-z: expected Z or NAME=Z,NAME=Z..., got '{}'", text));
    }
    o.groundZByCamera[lower(part.substr(0, equals))] =
        parseDouble("--ground-z", part.substr(equals + 1), -1e6, 1e6, "NAME=Z with Z a number");
  }
}

processing::LensModel parseLens(std::string_view text) {
  if (const auto model = processing::lensModelNamed(text)) return *model;
  throw UsageError(fmt::format("--lens: expected pinhole, fisheye or ocam, got '{}'", text));
}

}  // namespace

ImportOptions parseImport(std::span<const std::string_view> arguments) {
  ImportOptions o;
  o.commandLine = "surround-calibrate import";
  for (const auto argument : arguments) o.commandLine += " " + std::string(argument);
  parseOptions(
      arguments,
      {{"--camera", [&](auto v) { parseCamera(o, v); }},
       {"--pjlab", [&](auto v) { o.pjlabDir = std::string(v); }},
       {"--pjlab-yaml", [&](auto v) { o.pjlabYaml = std::string(v); }},
       {"--lens", [&](auto v) { o.lens = parseLens(v); }},
       {"--image-size", [&](auto v) { o.imageSize = parseSize("--image-size", v); }},
       {"--field-of-view-deg",
        [&](auto v) {
          o.fieldOfViewDeg = parseDouble("--field-of-view-deg", v, 1, 360, "degrees from 1 to 360");
        }},
       {"--axes",
        [&](auto v) {
          o.axes = parseAxes(v);
          o.axesText = std::string(v);
        }},
       {"--unit-m",
        [&](auto v) { o.unitM = parseDouble("--unit-m", v, 1e-9, 1e6, "metres per source unit"); }},
       {"--ground-z", [&](auto v) { parseGround(o, v); }},
       {"--offset-m",
        [&](auto v) {
          const auto xyz = parseNumbers("--offset-m", v, 3, "X,Y,Z in metres");
          o.offsetM = {xyz[0], xyz[1], xyz[2]};
        }},
       {"--pose-direction",
        [&](auto v) {
          if (v != "to-camera" && v != "to-source") {
            throw UsageError(
                fmt::format("--pose-direction: expected to-camera or to-source, got '{}'", v));
          }
          o.poseDirection = v == "to-camera" ? PoseDirection::kToCamera : PoseDirection::kToSource;
        }},
       {"--canvas-scale",
        [&](auto v) {
          o.canvasScale = parseDouble("--canvas-scale", v, 1e-12, 1e6, "source units per pixel");
        }},
       {"--canvas-origin",
        [&](auto v) {
          const auto uv = parseNumbers("--canvas-origin", v, 2, "OU,OV in canvas pixels");
          o.canvasOrigin = {uv[0], uv[1]};
        }},
       {"--canvas-strips", [&](auto v) { o.canvasStrips = parseSize("--canvas-strips", v); }},
       {"--out", [&](auto v) { o.out = std::string(v); }},
       {"--images", [&](auto v) { o.images = std::string(v); }}},
      {{"--origin-centre", [&](auto) { o.originCentre = true; }}});
  const int inputs = (o.cameraFiles.empty() ? 0 : 1) + (o.pjlabDir ? 1 : 0) + (o.pjlabYaml ? 1 : 0);
  if (inputs == 0) throw UsageError("missing the input: --camera, --pjlab or --pjlab-yaml");
  if (inputs > 1) {
    throw UsageError("give one kind of input: --camera, --pjlab or --pjlab-yaml, not several");
  }
  if (o.out.empty()) throw UsageError("--out: missing (the rig file to write)");
  if (o.fieldOfViewDeg && o.lens && *o.lens == processing::LensModel::kPinhole) {
    throw UsageError("--field-of-view-deg: only a fisheye or ocam lens takes it");
  }
  return o;
}

}  // namespace surroundd::calibrate
