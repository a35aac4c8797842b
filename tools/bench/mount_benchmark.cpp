#include "tools/bench/mount_benchmark.hpp"

#include <chrono>
#include <cmath>
#include <ctime>
#include <memory>
#include <numbers>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "capture/file_source.hpp"
#include "processing/calibration/agreed_corrections.hpp"
#include "processing/calibration/mount_refinement.hpp"
#include "tools/bench/recording_truth.hpp"

namespace surroundd::bench {
namespace {

constexpr double kCompareEveryS = 1;  // calibration_watch.compare_every_s's default
constexpr double kDegree = std::numbers::pi / 180;

struct Knock {
  std::size_t camera = 0;
  double atS = 0;
  cv::Matx33d after;  // the mount's rotation from atS on
};

double degreesBetween(const cv::Matx33d& a, const cv::Matx33d& b) {
  cv::Vec3d rotation;
  cv::Rodrigues(a.t() * b, rotation);
  return cv::norm(rotation) / kDegree;
}

double cpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

void report(const std::filesystem::path& folder) {
  RecordingTruth truth = loadRecordingTruth(folder);
  const YAML::Node written = YAML::LoadFile((folder / "ground_truth.yaml").string());
  std::optional<Knock> knock;
  for (std::size_t c = 0; c < truth.rig.cameras.size(); ++c) {
    const YAML::Node camera = written["cameras"][c];
    // The body masked as rendered (what surround-calibrate mask --from finds).
    if (camera["body_mask"]) {
      truth.rig.cameras[c].bodyMask = cv::imread(
          (folder / camera["body_mask"].as<std::string>()).string(), cv::IMREAD_GRAYSCALE);
    }
    if (const YAML::Node after = camera["mount_after_turn"]) {
      knock = Knock{c, camera["turned_at_s"].as<double>(),
                    processing::rotationFromMountAngles({after["yaw_deg"].as<double>(),
                                                         after["pitch_deg"].as<double>(),
                                                         after["roll_deg"].as<double>()})};
    }
  }
  processing::PanoramaSettings settings;
  settings.geometry = truth.panorama;
  processing::MountRefinement refinement(truth.rig, settings);

  std::vector<std::unique_ptr<capture::FileSource>> sources;
  for (const auto& camera : truth.rig.cameras) {
    sources.push_back(std::make_unique<capture::FileSource>(
        camera.name, capture::FileSourceSettings{folder / (camera.name + ".mkv"), 30, false,
                                                 capture::Pacing::kAsFastAsPossible}));
  }
  const double periodS = std::chrono::duration<double>(sources.front()->nominalPeriod()).count();
  std::vector<capture::Frame> frames(sources.size());
  std::vector<const cv::Mat*> pictures(sources.size());
  for (std::size_t c = 0; c < sources.size(); ++c) {
    frames[c].image.create(sources[c]->frameSize(), CV_8UC3);
    pictures[c] = &frames[c].image;
  }

  fmt::print("{}: {} patches, ", folder.filename().string(), refinement.patches());
  if (knock) {
    const auto change = processing::mountAngleChange(
        truth.rig.cameras[knock->camera].pose,
        {knock->after, truth.rig.cameras[knock->camera].pose.position});
    fmt::print("camera '{}' knocked at {:g} s by yaw {:+.1f}, pitch {:+.1f}, roll {:+.1f} deg\n",
               truth.rig.cameras[knock->camera].name, knock->atS, change.yawDeg, change.pitchDeg,
               change.rollDeg);
  } else {
    fmt::print("no camera knocked\n");
  }

  std::size_t compared = 0;
  std::size_t falseAlarms = 0;
  double cpu = 0;
  double nextS = 0;
  std::optional<double> firstS;   // of a correction worth applying to the knocked camera
  std::optional<double> withinS;  // of one within 0.1 degrees of its mount after the turn
  // correct: apply's: two solutions in a row agree on it.
  processing::AgreedCorrections agreements;
  std::optional<double> appliedS;
  double appliedError = 0;
  std::size_t falseCorrections = 0;
  std::optional<processing::MountRefinementResult> last;
  for (int k = 0;; ++k) {
    bool all = true;
    for (std::size_t c = 0; c < sources.size() && all; ++c) {
      all = sources[c]->read(frames[c]) == capture::ReadStatus::kFrame;
    }
    if (!all) break;
    const double t = k * periodS;
    if (t + 1e-9 < nextS) continue;
    nextS = t + kCompareEveryS;
    const double before = cpuSeconds();
    auto solved = refinement.track(pictures);
    cpu += cpuSeconds() - before;
    ++compared;
    if (!solved) continue;
    last = solved;
    for (const std::size_t c : agreements.add(*solved, truth.rig)) {
      if (!knock || c != knock->camera || t < knock->atS) {
        ++falseCorrections;
        continue;
      }
      if (appliedS) continue;
      appliedS = t;
      appliedError = degreesBetween(solved->cameras[c].applied(truth.rig.cameras[c].pose).rotation,
                                    knock->after);
    }
    for (std::size_t c = 0; c < solved->cameras.size(); ++c) {
      const auto& correction = solved->cameras[c];
      if (solved->verdict(c) != processing::CorrectionVerdict::kOffered) continue;
      const bool knocked = knock && c == knock->camera && t >= knock->atS;
      if (!knocked) {
        ++falseAlarms;
        fmt::print("  {:6.1f} s: false alarm: camera '{}' by {:.2f} deg\n", t,
                   truth.rig.cameras[c].name, correction.angleDeg());
        continue;
      }
      const double error =
          degreesBetween(correction.applied(truth.rig.cameras[c].pose).rotation, knock->after);
      if (!firstS) firstS = t;
      if (!withinS && error <= 0.1) withinS = t;
      fmt::print("  {:6.1f} s: camera '{}' corrected to {:.3f} deg of its mount after the turn\n",
                 t, truth.rig.cameras[c].name, error);
    }
  }
  const double sets = static_cast<double>(std::max<std::size_t>(compared, 1));
  fmt::print(
      "  {} sets compared over {:.0f} s, {:.1f} ms of CPU each ({:.1f} % of one core at "
      "one a second), {} false alarms, {} corrections correct: apply would make wrongly\n",
      compared, static_cast<double>(compared) * kCompareEveryS, 1e3 * cpu / sets,
      100 * cpu / sets / kCompareEveryS, falseAlarms, falseCorrections);
  if (knock) {
    const auto after = [&](const std::optional<double>& s) {
      return s ? fmt::format("{:.0f} s after the turn", *s - knock->atS) : std::string("never");
    };
    fmt::print("  knocked camera: a correction worth applying {}, within 0.1 deg {}\n",
               after(firstS), after(withinS));
    fmt::print("  correct: apply makes it {}{}\n", after(appliedS),
               appliedS ? fmt::format(", {:.2f} deg from its mount after the turn", appliedError)
                        : std::string());
  }
  if (last) {
    for (const auto& seam : last->seams) {
      fmt::print("  seam {}: {:.1f} -> {:.1f} cm ({} comparisons)\n", seam.name, seam.beforeCm,
                 seam.afterCm, seam.matches);
    }
  }
}

}  // namespace

int runMountBenchmark(const std::vector<std::filesystem::path>& recordings) {
  int status = 0;
  for (const auto& folder : recordings) {
    try {
      report(folder);
    } catch (const std::exception& error) {
      fmt::print(stderr, "surround-bench mounts: {}: {}\n", folder.string(), error.what());
      status = 1;
    }
  }
  return status;
}

}  // namespace surroundd::bench
