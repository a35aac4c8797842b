#include "tools/calibrate/refine/refine_command.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "capture/file_source.hpp"
#include "common/work_pool.hpp"
#include "daemon/config/config.hpp"
#include "daemon/config/panorama_setup.hpp"
#include "processing/calibration/ground_top_view.hpp"
#include "processing/calibration/mount_refinement.hpp"
#include "tools/calibrate/calibration_output.hpp"
#include "tools/calibrate/camera_pictures.hpp"
#include "tools/calibrate/recorded_camera.hpp"

namespace surroundd::calibrate {
namespace {

constexpr int kPasses = 3;
constexpr int kMostSets = 240;
// The pictures from above: this far from the vehicle's centre each way, at this scale.
constexpr double kTopReachM = 6;
constexpr double kTopMetresPerPx = 0.0125;

struct Setup {
  daemon::Config config;
  std::optional<std::filesystem::path> rigFile;  // none: the config's rig is inline
  processing::Rig rig;                           // with the body masks surroundd uses
};

Setup load(const RefineOptions& options) {
  Setup setup;
  if (!options.config.empty()) {
    setup.config = daemon::loadConfig(options.config);
    setup.rigFile = setup.config.rigFile;
  } else {
    setup.rigFile = recordingRigFile(options.rig);
    daemon::RigFile rig = daemon::loadRig(*setup.rigFile);
    setup.config.file = *setup.rigFile;
    setup.config.cameras = std::move(rig.cameras);
    setup.config.vehicle = rig.vehicle;
  }
  WorkPool pool;
  for (std::size_t c = 0; c < setup.config.cameras.size(); ++c) {
    processing::CameraCalibration camera = setup.config.cameras[c].calibration;
    try {
      camera.bodyMask = daemon::bodyMaskOf(setup.config, c, pool);
    } catch (const std::runtime_error& error) {
      throw UsageError(error.what());  // a body_mask.file that does not fit the lens
    }
    setup.rig.cameras.push_back(std::move(camera));
  }
  return setup;
}

using SetVisitor = std::function<void(const std::vector<cv::Mat>&)>;

// One still picture per camera from `folder`: one set.
void visitStills(const Setup& setup, const std::filesystem::path& folder, const SetVisitor& visit) {
  std::vector<cv::Mat> set;
  for (const processing::CameraCalibration& camera : setup.rig.cameras) {
    const std::filesystem::path file = requirePicture(folder, camera.name);
    cv::Mat picture = cv::imread(file.string(), cv::IMREAD_COLOR);
    if (picture.empty()) {
      throw UsageError(fmt::format("{}: cannot read the picture", file.string()));
    }
    checkPictureSize(file, picture.size(), camera, setup.rigFile.value_or(setup.config.file));
    set.push_back(std::move(picture));
  }
  visit(set);
}

// The cameras' recorded sources side by side, frame by frame (as surroundd's recording output and
// the generator write them), one set every `everyS` seconds; a still picture is one set.
void visitRecording(const Setup& setup, double everyS, const SetVisitor& visit) {
  std::vector<std::unique_ptr<capture::FileSource>> sources;
  double periodS = 0;
  for (const daemon::RigCamera& camera : setup.config.cameras) {
    sources.push_back(openRecordedCamera(camera, setup.rigFile.value_or(setup.config.file)));
    periodS =
        std::max(periodS, std::chrono::duration<double>(sources.back()->nominalPeriod()).count());
  }
  const int every = std::max(1, static_cast<int>(std::lround(everyS / std::max(periodS, 1e-3))));
  std::vector<capture::Frame> frames(sources.size());
  std::vector<cv::Mat> set(sources.size());
  for (std::size_t c = 0; c < sources.size(); ++c) {
    frames[c].image.create(sources[c]->frameSize(), CV_8UC3);
  }
  for (int index = 0, sets = 0; sets < kMostSets; ++index) {
    for (std::size_t c = 0; c < sources.size(); ++c) {
      if (sources[c]->read(frames[c]) != capture::ReadStatus::kFrame) return;
    }
    if (index % every != 0) continue;
    for (std::size_t c = 0; c < sources.size(); ++c) set[c] = frames[c].image;
    visit(set);
    ++sets;
  }
}

void visitSets(const Setup& setup, const RefineOptions& options, const SetVisitor& visit) {
  if (options.images) {
    visitStills(setup, *options.images, visit);
  } else {
    visitRecording(setup, options.everyS, visit);
  }
}

std::string describe(const processing::MountCorrection& correction,
                     const processing::Pose& before) {
  const auto change = processing::mountAngleChange(before, correction.applied(before));
  const cv::Vec3d sigma = correction.rotationSigmaRad * (180 / std::numbers::pi);
  return fmt::format(
      "yaw {:+.2f}, pitch {:+.2f}, roll {:+.2f} deg (+-{:.2f}), height {:+.1f} cm (+-{:.1f})",
      change.yawDeg, change.pitchDeg, change.rollDeg, std::max({sigma[0], sigma[1], sigma[2]}),
      100 * correction.heightM, 100 * correction.heightSigmaM);
}

std::string whyLeft(processing::CorrectionVerdict verdict) {
  switch (verdict) {
    case processing::CorrectionVerdict::kUncertain:
      return "is too uncertain to act on";
    case processing::CorrectionVerdict::kTooLarge:
      return fmt::format(
          "turns it more than {:g} deg: a fault, not a drift (check its mount, or calibrate it "
          "again: surround-calibrate extrinsics)",
          processing::MountRefinementResult::kLargestTurnDeg);
    case processing::CorrectionVerdict::kTooSmall:
      return fmt::format("turns it less than {:g} deg",
                         processing::MountRefinementResult::kSmallestTurnDeg);
    case processing::CorrectionVerdict::kSeamsApart:
      return "leaves its seams apart (the patches cannot reach that far: check its mount)";
    case processing::CorrectionVerdict::kHeld:
    case processing::CorrectionVerdict::kOffered:
      break;
  }
  return "";
}

cv::Mat topView(const processing::Rig& rig, const std::vector<cv::Mat>& set) {
  const int side = static_cast<int>(2 * kTopReachM / kTopMetresPerPx);
  return processing::stitchedTopView(rig.cameras, set, {{0, 0}, kTopMetresPerPx, {side, side}});
}

}  // namespace

void runRefine(const RefineOptions& options, std::ostream& log) {
  const Setup setup = load(options);
  if (options.updateRig && !setup.rigFile) {
    throw UsageError(
        fmt::format("--update-rig: {} holds its cameras inline, not in a rig file; "
                    "paste {} into it instead",
                    options.config.string(), (options.out / "mounts.yaml").string()));
  }
  const processing::PanoramaSettings settings = daemon::panoramaSettings(setup.config);
  processing::MountRefinement refinement(setup.rig, settings);
  std::vector<cv::Mat> firstSet;
  std::optional<processing::MountRefinementResult> result;
  for (int pass = 0; pass < kPasses; ++pass) {
    if (result) refinement.follow(*result);
    visitSets(setup, options, [&](const std::vector<cv::Mat>& set) {
      if (firstSet.empty()) {
        for (const cv::Mat& picture : set) firstSet.push_back(picture.clone());
      }
      std::vector<const cv::Mat*> pictures(set.size());
      std::ranges::transform(set, pictures.begin(), [](const cv::Mat& p) { return &p; });
      refinement.add(pictures);
    });
    result = refinement.solve();
    if (!result) {
      throw UsageError(fmt::format(
          "too little ground that two cameras both see, with texture enough to compare: {} "
          "comparisons in {} patches (a camera needs {} on its seams). Drive over ground with "
          "some texture (asphalt, lines, gravel), and mask the body (--config with a vehicle:)",
          refinement.matches(), refinement.patches(), processing::MountRefinement::kMinMatches));
    }
  }
  if (firstSet.empty()) throw UsageError("no picture could be read");

  log << fmt::format("{} comparisons kept from {} sets, {} left out as disagreeing\n",
                     result->matches, result->sets, result->rejected);
  processing::Rig refined = setup.rig;
  std::vector<std::pair<std::string, processing::Pose>> mounts;
  for (std::size_t c = 0; c < setup.rig.cameras.size(); ++c) {
    const processing::CameraCalibration& camera = setup.rig.cameras[c];
    const processing::MountCorrection& correction = result->cameras[c];
    using processing::CorrectionVerdict;
    const CorrectionVerdict verdict = result->verdict(c);
    if (verdict == CorrectionVerdict::kHeld) {
      log << fmt::format("{}: held (the others turn least around it)\n", camera.name);
      continue;
    }
    if (verdict != CorrectionVerdict::kOffered) {
      log << fmt::format("{}: left as it is: {} {}\n", camera.name,
                         describe(correction, camera.pose), whyLeft(verdict));
      continue;
    }
    log << fmt::format("{}: {}\n", camera.name, describe(correction, camera.pose));
    refined.cameras[c].pose = correction.applied(camera.pose);
    mounts.emplace_back(camera.name, refined.cameras[c].pose);
  }
  for (const processing::SeamFit& seam : result->seams) {
    log << fmt::format("seam {}: {:.1f} -> {:.1f} cm ({} comparisons)\n", seam.name, seam.beforeCm,
                       seam.afterCm, seam.matches);
  }

  std::filesystem::create_directories(options.out);
  writePng(options.out / "top-before.png", topView(setup.rig, firstSet));
  writePng(options.out / "top-after.png", topView(refined, firstSet));
  const std::string comment = "refined from the road by surround-calibrate refine";
  writeMountBlocks(options.out / "mounts.yaml", mounts, comment);
  log << fmt::format("wrote {}, {}, {}\n", (options.out / "mounts.yaml").string(),
                     (options.out / "top-before.png").string(),
                     (options.out / "top-after.png").string());
  if (!options.updateRig || mounts.empty()) return;
  const std::filesystem::path before = setup.rigFile->string() + ".before-refine";
  std::filesystem::copy_file(*setup.rigFile, before,
                             std::filesystem::copy_options::overwrite_existing);
  updateRigMounts(*setup.rigFile, mounts, comment);
  log << fmt::format("updated {} (the file before: {})\n", setup.rigFile->string(),
                     before.string());
}

}  // namespace surroundd::calibrate
