#include "tools/calibrate/mask/drive_mask_command.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "capture/file_source.hpp"
#include "common/work_pool.hpp"
#include "daemon/config/config.hpp"
#include "daemon/config/panorama_setup.hpp"
#include "processing/calibration/body_from_motion.hpp"
#include "tools/calibrate/calibration_output.hpp"
#include "tools/calibrate/mask/mask_overlay.hpp"
#include "tools/calibrate/recorded_camera.hpp"

namespace surroundd::calibrate {
namespace {

// Fewer pairs of pictures say too little: a pixel's "mostly still" needs a few dozen looks.
constexpr int kMinPairs = 12;
// A drive this long is plenty; longer ones are looked at in part.
constexpr int kMostPictures = 600;
// A drive moves most of the ground a camera sees below the horizon; a parked car almost none.
constexpr double kMinMovingShare = 0.3;
// Polygons within a pixel of the mask's outline.
constexpr double kOutlineTolerancePx = 1.0;

struct FoundBody {
  cv::Mat mask;
  cv::Mat lastPicture;
  int pictures = 0;
  double movingShare = 0;
};

// Every `everyS` seconds of the camera's recording, its picture given to the finder.
FoundBody findBody(const daemon::RigCamera& camera, const std::filesystem::path& recording,
                   double everyS) {
  const std::string& name = camera.calibration.name;
  const auto source = openRecordedCamera(camera, recording);
  const std::filesystem::path& path = camera.replayedFile()->path;
  const cv::Size size = camera.calibration.intrinsics.imageSize;
  FoundBody found;
  try {
    const double periodS = std::chrono::duration<double>(source->nominalPeriod()).count();
    const int every = std::max(1, static_cast<int>(std::lround(everyS / periodS)));
    processing::BodyFromMotion finder(camera.calibration);
    capture::Frame frame;
    frame.image.create(size, CV_8UC3);
    for (int index = 0; found.pictures < kMostPictures; ++index) {
      if (source->read(frame) != capture::ReadStatus::kFrame) break;
      if (index % every != 0) continue;
      finder.add(frame.image);
      ++found.pictures;
    }
    if (finder.pairs() < kMinPairs) {
      const int needed = kMinPairs + processing::BodyFromMotionSettings{}.span;
      throw UsageError(fmt::format(
          "camera '{}': {} gives {} pictures {:g} s apart; at least {} are needed (a drive of "
          "{:.2g} s or more, or a smaller --every)",
          name, path.string(), found.pictures, every * periodS, needed, needed * every * periodS));
    }
    found.movingShare = finder.movingShare();
    if (found.movingShare < kMinMovingShare) {
      throw UsageError(fmt::format(
          "camera '{}': only {:.0f} % of the ground it sees changed in {}: the car must drive "
          "while it records (a few metres at least, past ground with some texture)",
          name, 100 * found.movingShare, path.string()));
    }
    found.mask = finder.mask();
    frame.image.copyTo(found.lastPicture);
  } catch (const capture::CaptureError& error) {
    throw UsageError(error.what());
  }
  return found;
}

// `{mode: add, polygon: [[[u, v], ...], ...]}`.
std::string addedPolygonsYaml(const std::vector<std::vector<cv::Point>>& polygons) {
  YAML::Emitter out;
  out << YAML::Flow << YAML::BeginMap << YAML::Key << "mode" << YAML::Value << "add";
  out << YAML::Key << "polygon" << YAML::Value << YAML::BeginSeq;
  for (const auto& polygon : polygons) {
    out << YAML::BeginSeq;
    for (const cv::Point& p : polygon) out << YAML::BeginSeq << p.x << p.y << YAML::EndSeq;
    out << YAML::EndSeq;
  }
  out << YAML::EndSeq << YAML::EndMap;
  return out.c_str();
}

}  // namespace

void runDriveMask(const MaskOptions& options, std::ostream& log) {
  const std::filesystem::path rigFile = recordingRigFile(options.from);
  const daemon::RigFile rig = daemon::loadRig(rigFile);
  // What surroundd would mask (the rig's vehicle and the cameras' own masks), to compare.
  daemon::Config config;
  config.file = rigFile;
  config.cameras = rig.cameras;
  config.vehicle = rig.vehicle;
  WorkPool pool;

  std::vector<std::pair<std::string, std::string>> yaml;  // cameras with a body found
  int looked = 0;
  std::string names;
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
    const daemon::RigCamera& camera = rig.cameras[c];
    const std::string& name = camera.calibration.name;
    names += (names.empty() ? "" : ", ") + name;
    if (!options.camera.empty() && name != options.camera) continue;
    const FoundBody found = findBody(camera, rigFile, options.everyS);
    cv::Mat computed = daemon::bodyMaskOf(config, c, pool);
    if (computed.empty()) computed = cv::Mat::zeros(found.mask.size(), CV_8U);

    const double area = static_cast<double>(found.mask.total());
    const double share = 100.0 * cv::countNonZero(found.mask) / area;
    const double missed = 100.0 * cv::countNonZero(found.mask & ~computed) / area;
    const auto polygons = processing::maskOutlines(found.mask, kOutlineTolerancePx);
    const auto bodyFile = options.out / (name + "-found-body.png");
    const auto overlayFile = options.out / (name + "-found-overlay.png");
    writePng(bodyFile, found.mask);
    writePng(overlayFile,
             maskOverlay(
                 found.lastPicture, found.mask,
                 {name, fmt::format("{:.1f} % body, found in {} pictures", share, found.pictures),
                  fmt::format("{:.1f} % of it not in the computed mask", missed)}));
    log << fmt::format(
        "{}: {:.1f} % of the picture is body ({} pictures, {:.0f} % of the ground moved); "
        "{:.1f} % is body the vehicle's mask leaves out: {}, {}\n",
        name, share, found.pictures, 100 * found.movingShare, missed, overlayFile.string(),
        bodyFile.string());
    if (!polygons.empty()) yaml.emplace_back(name, addedPolygonsYaml(polygons));
    ++looked;
  }
  if (looked == 0) {
    throw UsageError(fmt::format("--camera: {} has no camera '{}' (its cameras: {})",
                                 rigFile.string(), options.camera, names));
  }
  if (yaml.empty()) {
    log << "\nNo camera shows a body that stays: nothing to add to the rig.\n";
    return;
  }
  log << "\nTo mask the body found besides the vehicle's, give each camera in the rig (a camera "
         "with a body_mask: already: join the polygons to its own):\n";
  for (const auto& [name, mask] : yaml) {
    log << fmt::format("  - name: {}\n    body_mask: {}\n", name, mask);
  }
}

}  // namespace surroundd::calibrate
