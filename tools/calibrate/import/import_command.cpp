#include "tools/calibrate/import/import_command.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <optional>
#include <string_view>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <opencv2/imgcodecs.hpp>

#include "tools/calibrate/calibrate_options.hpp"
#include "tools/calibrate/camera_pictures.hpp"
#include "tools/calibrate/import/canvas_strips.hpp"
#include "tools/calibrate/import/foreign_lens.hpp"
#include "tools/calibrate/import/ground_homography.hpp"
#include "tools/calibrate/import/ocam_results.hpp"
#include "tools/calibrate/import/pjlab_layout.hpp"

namespace surroundd::calibrate {
namespace {

constexpr std::array<std::string_view, 4> kRigOrder{"front", "right", "back", "left"};

std::string lower(std::string text) {
  std::ranges::transform(text, text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

std::vector<NamedCalibration> readInputs(const ImportOptions& options) {
  std::vector<NamedCalibration> cameras;
  if (options.pjlabYaml) return readPjlabYaml(*options.pjlabYaml, options.poseDirection);
  const auto files = options.pjlabDir
                         ? pjlabCameraFiles(*options.pjlabDir)
                         : std::vector<std::pair<std::string, std::vector<std::filesystem::path>>>(
                               options.cameraFiles.begin(), options.cameraFiles.end());
  for (const auto& [name, paths] : files) {
    NamedCalibration camera{name, {}};
    for (const auto& path : paths) {
      if (path.extension() == ".txt") {
        if (!camera.calibration.lens) {
          camera.calibration.lens =
              Found<processing::Intrinsics>{readOcamResults(path), path.string()};
        }
        camera.calibration.files.push_back(path);
      } else {
        readOpenCvCalibration(path, options.poseDirection, camera.calibration);
      }
    }
    cameras.push_back(std::move(camera));
  }
  return cameras;
}

// A fit to a homography further from it than this gets a warning: hand-clicked points give a
// pixel or so, a wrong --canvas-scale or canvas many.
constexpr double kPoorFitPx = 2;
constexpr double kPoorFitM = 0.05;

// The camera matrix of the undistorted picture the homography maps to.
cv::Matx33d undistortedCamera(const ForeignCalibration& found, const processing::Intrinsics& lens) {
  const cv::Vec2d scale = found.undistortedScale ? found.undistortedScale->value : cv::Vec2d(1, 1);
  const cv::Vec2d shift = found.undistortedShift ? found.undistortedShift->value : cv::Vec2d(0, 0);
  return {lens.fx * scale[0],
          0,
          lens.cx + shift[0],
          0,
          lens.fy * scale[1],
          lens.cy + shift[1],
          0,
          0,
          1};
}

// The homography from the whole canvas to the undistorted picture: with --canvas-strips, through
// the camera's strip.
cv::Matx33d canvasToPicture(const std::string& camera, const ForeignCalibration& found,
                            const ImportOptions& options) {
  if (!options.canvasStrips) return found.homography->value;
  const auto side = sideInName(camera);
  if (!side) {
    throw UsageError(fmt::format(
        "--canvas-strips: camera '{}' has no side in its name (front, back, left or right), "
        "so its strip of the canvas is not known",
        camera));
  }
  return found.homography->value * stripFromCanvas(*side, *options.canvasStrips);
}

processing::Pose poseOf(const std::string& camera, const ForeignCalibration& found,
                        const processing::Intrinsics& lens, const ImportOptions& options,
                        const SourceFrame& frame, std::vector<std::string>& notes) {
  if (found.pose) return vehiclePose(frame, camera, found.pose->value);
  if (!found.homography) {
    std::string files;
    for (const auto& file : found.files) files += (files.empty() ? "" : ", ") + file.string();
    throw UsageError(
        fmt::format("camera '{}': no pose in {} (keys rvec + tvec, R + t, a 4x4 T / sensor_calib / "
                    "T_cam_from_G / extrinsic / transform, or a homography H)",
                    camera, files));
  }
  const auto& origin = found.homography->origin;
  if (!options.canvasScale) {
    throw UsageError(fmt::format(
        "{}: a ground homography needs --canvas-scale (source units per canvas pixel) and "
        "--canvas-origin",
        origin));
  }
  if (lens.model == processing::LensModel::kOcam) {
    throw UsageError(
        fmt::format("{}: an ocam lens has no camera matrix to decompose H with", origin));
  }
  if (frame.verticalAxis() != 2) {
    throw UsageError(fmt::format(
        "{}: a ground canvas lies in the source's x-y plane, so its z axis must be up or down "
        "(--axes {})",
        origin, options.axesText));
  }
  const GroundCanvas canvas{*options.canvasScale, options.canvasOrigin, frame.groundFor(camera),
                            frame.verticalSign()};
  const GroundPoseFit fit =
      poseFromGroundHomography(canvasToPicture(camera, found, options),
                               undistortedCamera(found, lens), lens.imageSize, canvas, origin);
  const double groundM = fit.rmsGroundUnits * options.unitM;
  const bool poor = fit.rmsPx > kPoorFitPx || groundM > kPoorFitM;
  notes.push_back(fmt::format(
      "{}camera '{}': pose fitted to the homography ({}) over {} ground points: {:.2f} px, "
      "{:.1f} cm RMS from it{}",
      poor ? "warning: " : "", camera, origin, fit.points, fit.rmsPx, 100 * groundM,
      poor ? "; it is not the ground seen by a camera: check --canvas-scale, --canvas-origin and "
             "the lens, or the points H was made from"
           : ""));
  return vehiclePose(frame, camera, fit.pose);
}

// A warning where a camera named front, back, left or right is placed or looks another way (an
// inverted matrix put a camera named 'back' in front of the car, looking forward, silently).
std::optional<std::string> nameAndPoseDisagree(const processing::CameraCalibration& camera) {
  const auto side = sideInName(camera.name);
  if (!side) return std::nullopt;
  const cv::Vec3d axis = camera.pose.rotation * cv::Vec3d(0, 0, 1);
  const cv::Vec2d looks(axis[0], axis[1]), at(camera.pose.position[0], camera.pose.position[1]);
  // Against the side's direction: looking more than 90 degrees away from it, or placed on the
  // other side of the vehicle's centre.
  const bool looksAway = cv::norm(looks) > 0.2 && looks.dot(side->direction) < 0;
  const bool placedAway = at.dot(side->direction) < -0.1;
  if (!looksAway && !placedAway) return std::nullopt;
  return fmt::format(
      "warning: camera '{}' is {}{}{}: its name says {}; check the pose's direction "
      "(--pose-direction) or the camera's name",
      camera.name, placedAway ? fmt::format("placed at x {:+.2f} y {:+.2f} m", at[0], at[1]) : "",
      placedAway && looksAway ? " and " : "",
      looksAway ? fmt::format("looking towards x {:+.2f} y {:+.2f}", looks[0], looks[1]) : "",
      side->name);
}

// What the camera's calibration was taken from, part by part.
std::string takenFrom(const std::string& camera, const ForeignCalibration& found,
                      const ImportOptions& options) {
  std::vector<std::string> parts;
  const auto add = [&](std::string_view what, const auto& part) {
    if (part) parts.push_back(fmt::format("{} from {}", what, part->origin));
  };
  add("lens", found.lens);
  add("camera matrix", found.cameraMatrix);
  add("distortion", found.distortion);
  add("lens model", found.modelName);
  add("image size", found.imageSize);
  add("pose", found.pose);
  add("ground homography", found.homography);
  add("undistorted fx, fy scale", found.undistortedScale);
  add("undistorted cx, cy shift", found.undistortedShift);
  if (options.lens)
    parts.push_back(
        fmt::format("lens model {} from --lens", processing::lensModelName(*options.lens)));
  if (options.imageSize) parts.emplace_back("image size from --image-size");
  if (found.homography && options.canvasStrips) {
    parts.push_back(fmt::format("its strip of the canvas: the {} one (--canvas-strips)",
                                sideInName(camera)->name));
  }
  return fmt::format("camera '{}': {}", camera, fmt::join(parts, "; "));
}

std::string headerComment(const ImportOptions& options,
                          const std::vector<NamedCalibration>& inputs) {
  std::string files;
  for (const auto& input : inputs) {
    for (const auto& file : input.calibration.files) {
      if (files.find(file.string()) == std::string::npos) files += "\n  " + file.string();
    }
  }
  std::string ground = fmt::format("{}", options.groundZ);
  for (const auto& [camera, z] : options.groundZByCamera)
    ground += fmt::format(", {} {}", camera, z);
  return fmt::format(
      "Imported by surround-calibrate import from:{}\n"
      "Source frame: axes (x, y, z) = {}, unit {} m, ground at {} source units on the vertical "
      "axis; poses map {}; origin: {}{}.\n"
      "Written in the vehicle frame: origin on the ground under the vehicle centre, x forward, "
      "y left, z up, metres.\n"
      "Command: {}",
      files, options.axesText, options.unitM, ground,
      options.poseDirection == PoseDirection::kToCamera ? "source to camera" : "camera to source",
      options.originCentre ? "the centre of the cameras' bounding box" : "the source origin",
      cv::norm(options.offsetM) > 0
          ? fmt::format(", then moved by ({}, {}, {}) m", options.offsetM[0], options.offsetM[1],
                        options.offsetM[2])
          : "",
      options.commandLine);
}

}  // namespace

ImportedRig importRig(const ImportOptions& options) {
  const SourceFrame frame{options.axes, options.unitM, options.groundZ, options.groundZByCamera};
  const auto inputs = readInputs(options);
  for (const auto& byCamera : options.groundZByCamera) {
    // Named, not a structured binding: clang before 16 cannot capture one in a lambda.
    const std::string& camera = byCamera.first;
    if (std::ranges::none_of(inputs,
                             [&](const auto& in) { return lower(in.sourceName) == camera; })) {
      throw UsageError(fmt::format("--ground-z: there is no camera '{}'", camera));
    }
  }
  std::vector<daemon::RigCamera> cameras;
  std::vector<std::string> notes, sources;
  for (const auto& input : inputs) {
    daemon::RigCamera camera;
    auto& c = camera.calibration;
    c.name = lower(input.sourceName);
    const auto picture =
        options.images ? findPicture(*options.images, input.sourceName) : std::nullopt;
    cv::Mat image;
    if (picture) {
      image = cv::imread(picture->string(), cv::IMREAD_COLOR);
      if (image.empty()) {
        throw UsageError(fmt::format("{}: cannot read the picture", picture->string()));
      }
      // Relative to the rig file, so that the rig and the pictures can move together.
      const auto folder = std::filesystem::absolute(options.out).parent_path();
      camera.source = capture::FileSourceSettings{};
      camera.replayedFile()->path =
          std::filesystem::absolute(*picture).lexically_normal().lexically_relative(
              folder.lexically_normal());
      camera.replayedFile()->loop = true;
    } else if (options.images) {
      throw UsageError(fmt::format("--images: no picture named '{}' (.png, .jpg, ...) in {}",
                                   input.sourceName, options.images->string()));
    }
    c.intrinsics = importedLens(c.name, input.calibration, options, image);
    if (!image.empty() && image.size() != c.intrinsics.imageSize) {
      throw UsageError(fmt::format("{} is {}x{}, but the calibration of camera '{}' is for {}x{}",
                                   picture->string(), image.cols, image.rows, c.name,
                                   c.intrinsics.imageSize.width, c.intrinsics.imageSize.height));
    }
    c.pose = poseOf(c.name, input.calibration, c.intrinsics, options, frame, notes);
    sources.push_back(takenFrom(c.name, input.calibration, options));
    cameras.push_back(std::move(camera));
  }
  std::vector<processing::Pose> poses;
  poses.reserve(cameras.size());
  for (const auto& camera : cameras) poses.push_back(camera.calibration.pose);
  const cv::Vec3d shift =
      (options.originCentre ? -boundingBoxCentre(poses) : cv::Vec3d()) + options.offsetM;
  for (auto& camera : cameras) {
    camera.calibration.pose.position += shift;
    camera.calibration.role = daemon::defaultRole(camera.calibration.pose);
  }
  const auto rank = [](const daemon::RigCamera& camera) {
    const auto it = std::ranges::find(kRigOrder, camera.calibration.name);
    return static_cast<int>(it - kRigOrder.begin());
  };
  std::ranges::stable_sort(cameras, {}, rank);
  for (const auto& camera : cameras) {
    if (auto warning = nameAndPoseDisagree(camera.calibration)) notes.push_back(*warning);
  }
  return {cameras, headerComment(options, inputs), notes, sources};
}

void runImport(const ImportOptions& options, std::ostream& log) {
  const auto [cameras, header, notes, sources] = importRig(options);
  for (const auto& source : sources) log << source << "\n";
  for (const auto& note : notes) log << note << "\n";
  if (options.out.has_parent_path()) std::filesystem::create_directories(options.out.parent_path());
  daemon::writeRigFile(options.out, cameras, header);
  for (const auto& camera : cameras) {
    const auto& pose = camera.calibration.pose;
    const auto angles = processing::mountAnglesFromRotation(pose.rotation);
    log << fmt::format(
        "{:<6} x {:+.3f} y {:+.3f} z {:.3f} m, yaw {:+.2f} pitch {:+.2f} roll {:+.2f} deg{}\n",
        camera.calibration.name, pose.position[0], pose.position[1], pose.position[2],
        angles.yawDeg, angles.pitchDeg, angles.rollDeg,
        camera.replayedFile() ? ", picture " + camera.replayedFile()->path.string() : "");
  }
  log << "wrote " << options.out.string() << "\n";
}

}  // namespace surroundd::calibrate
