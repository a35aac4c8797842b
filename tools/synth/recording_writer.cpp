#include "tools/synth/recording_writer.hpp"

#include <chrono>
#include <map>
#include <memory>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <unistd.h>

#include "tools/synth/encode_worker.hpp"
#include "tools/synth/recording_plan.hpp"
#include "tools/synth/recording_yaml.hpp"
#include "tools/synth/scene.hpp"
#include "tools/synth/scene_renderer.hpp"

namespace surroundd::synth {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void writePng(const std::filesystem::path& file, const cv::Mat& image) {
  if (!cv::imwrite(file.string(), image)) {
    throw std::runtime_error(fmt::format("{}: cannot write the image", file.string()));
  }
}

// Removes the temporary folder unless the run got as far as publishing it.
class TemporaryFolder {
 public:
  explicit TemporaryFolder(std::filesystem::path path) : path_(std::move(path)) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_ / "ground_truth");
  }
  ~TemporaryFolder() {
    std::error_code ignored;
    if (!published_) std::filesystem::remove_all(path_, ignored);
  }
  TemporaryFolder(const TemporaryFolder&) = delete;
  TemporaryFolder& operator=(const TemporaryFolder&) = delete;

  const std::filesystem::path& path() const { return path_; }

  // Replaces `target` (if any) with this folder. The old one is moved aside first, so `target`
  // names either the old or the new complete recording, never a mixture.
  void publish(const std::filesystem::path& target) {
    const auto aside =
        std::filesystem::path(target.string() + ".old-" + std::to_string(::getpid()));
    const bool existed = std::filesystem::exists(target);
    if (existed) std::filesystem::rename(target, aside);
    std::filesystem::rename(path_, target);
    published_ = true;
    if (existed) std::filesystem::remove_all(aside);
  }

 private:
  std::filesystem::path path_;
  bool published_ = false;
};

}  // namespace

RecordingResult writeRecording(const SynthOptions& options, std::ostream& log) {
  const auto start = Clock::now();
  const RecordingPlan plan = planRecording(options);
  RecordingResult result;
  result.folder = options.out;
  result.frames = plan.frames;

  std::error_code ec;
  if (std::filesystem::exists(options.out, ec)) {
    if (readManifestKey(options.out / "manifest.yaml") == plan.key) {
      log << "up to date: " << options.out.string() << std::endl;
      result.upToDate = true;
      return result;
    }
    if (!options.force) {
      throw UsageError(fmt::format(
          "--out: '{}' exists and holds no recording made with these arguments; pass --force "
          "to replace it",
          options.out.string()));
    }
  }
  const auto outAbsolute = std::filesystem::absolute(options.out);
  if (!outAbsolute.parent_path().empty())
    std::filesystem::create_directories(outAbsolute.parent_path());
  TemporaryFolder folder(outAbsolute.string() + ".tmp-" + std::to_string(::getpid()));
  std::map<std::string, double> durations;

  // Set-up: everything heavy, once.
  auto stage = Clock::now();
  const Scene scene(options.seed, options.seconds, options.scene);
  durations["scene"] = secondsSince(stage);
  stage = Clock::now();
  std::optional<EgoBody> body;
  if (plan.vehicle) body.emplace(*plan.vehicle);
  std::vector<std::unique_ptr<CameraRays>> rays;
  std::vector<std::unique_ptr<CameraRays>> turnedRays;  // per camera; null: not knocked
  std::vector<std::unique_ptr<PhotometricCamera>> sensors, neutral;
  for (std::size_t c = 0; c < plan.cameras.size(); ++c) {
    const auto& calibration = plan.cameras[c].camera.calibration;
    rays.push_back(std::make_unique<CameraRays>(calibration, body ? &*body : nullptr));
    if (body) writePng(folder.path() / bodyMaskName(calibration.name), rays.back()->bodyMask());
    turnedRays.emplace_back();
    if (const auto& turned = plan.cameras[c].turnedPose) {
      processing::CameraCalibration knocked = calibration;
      knocked.pose = *turned;
      turnedRays.back() = std::make_unique<CameraRays>(knocked, body ? &*body : nullptr);
      if (body) {
        writePng(folder.path() / turnedBodyMaskName(calibration.name),
                 turnedRays.back()->bodyMask());
      }
    }
    sensors.push_back(std::make_unique<PhotometricCamera>(
        plan.cameras[c].photometrics, options.seed, static_cast<int>(c),
        rays.back()->offAxisAngle(), rays.back()->fisheye()));
    neutral.push_back(std::make_unique<PhotometricCamera>(
        identityPhotometrics(), options.seed, static_cast<int>(c), rays.back()->offAxisAngle(),
        rays.back()->fisheye()));
  }
  durations["rays"] = secondsSince(stage);

  std::vector<std::unique_ptr<EncodeWorker>> encoders;
  for (const auto& camera : plan.cameras) {
    render::VideoEncoderSettings settings;
    settings.path = folder.path() / (camera.camera.calibration.name + ".mkv");
    settings.size = camera.camera.calibration.intrinsics.imageSize;
    settings.nominalFps = options.fps;
    settings.crf = options.crf;
    // ultrafast: x264 at veryfast costs ~35 ms per 720p 4:4:4 frame at CRF 14 (the sensor noise is
    // expensive to keep), which alone would use most of the demo's one-minute budget on two
    // cores; ultrafast is ~10 ms at the same CRF (same quality, about three times the bytes).
    settings.preset = "ultrafast";
    settings.pixelFormat = "yuv444p";  // camera masters: no chroma subsampling on top of the noise
    settings.threads = 1;              // fixed, for identical bytes; the four run in parallel
    settings.bitExact = true;
    encoders.push_back(std::make_unique<EncodeWorker>(settings));
  }

  stage = Clock::now();
  double groundTruthS = 0;
  SceneRenderer renderer(scene);
  std::vector<CameraJob> jobs;
  jobs.reserve(plan.cameras.size());
  std::vector<cv::Mat> truth(plan.cameras.size());
  for (std::size_t c = 0; c < plan.cameras.size(); ++c) truth[c].create(rays[c]->size(), CV_8UC3);
  std::vector<int> framesWritten(plan.cameras.size(), 0);
  std::vector<cv::Mat> frozen(plan.cameras.size());  // the picture a frozen camera repeats
  auto nextTruth = plan.groundTruthFrames.begin();
  // The rays a camera sees through at frame k: as knocked from its turn on.
  const auto raysAt = [&](std::size_t c, int k) {
    return turnedRays[c] && k >= plan.cameras[c].turnFrame ? turnedRays[c].get() : rays[c].get();
  };
  for (int k = 0; k < plan.frames; ++k) {
    const double t = plan.frameTime(k);
    const VehiclePose pose = VehiclePath::poseAt(t);
    jobs.clear();
    for (std::size_t c = 0; c < plan.cameras.size(); ++c) {
      const CameraPlan& camera = plan.cameras[c];
      if (plan.dropped(c, k)) continue;
      cv::Mat& slot = encoders[c]->acquire();
      // Faults: a black picture, or the picture of the fault's first frame again and again.
      if (camera.faulty(k, SynthOptions::Fault::Kind::kBlack)) {
        slot.setTo(cv::Scalar::all(0));
      } else if (camera.faulty(k, SynthOptions::Fault::Kind::kFreeze) && k > camera.faultFrame) {
        frozen[c].copyTo(slot);
      } else {
        jobs.push_back({raysAt(c, k), sensors[c].get(), sensors[c]->frame(k, t), &slot});
      }
    }
    renderer.render(pose, jobs);
    for (std::size_t c = 0; c < plan.cameras.size(); ++c) {
      if (plan.dropped(c, k)) continue;
      if (plan.cameras[c].faulty(k, SynthOptions::Fault::Kind::kFreeze) &&
          k == plan.cameras[c].faultFrame) {
        encoders[c]->acquire().copyTo(frozen[c]);
      }
      encoders[c]->submit(plan.timestamp(c, k));
      ++framesWritten[c];
    }
    if (nextTruth != plan.groundTruthFrames.end() && *nextTruth == k) {
      const auto truthStart = Clock::now();
      jobs.clear();
      for (std::size_t c = 0; c < plan.cameras.size(); ++c) {
        jobs.push_back({raysAt(c, k), neutral[c].get(), neutral[c]->frame(k, t), &truth[c]});
      }
      renderer.render(pose, jobs);
      for (std::size_t c = 0; c < plan.cameras.size(); ++c) {
        writePng(folder.path() / cameraImageName(plan.cameras[c].camera.calibration.name, k),
                 truth[c]);
      }
      writePng(folder.path() / panoramaName(k),
               renderer.panorama(pose, plan.virtualCentre, options.panoramaSize));
      groundTruthS += secondsSince(truthStart);
      ++nextTruth;
    }
  }
  for (auto& encoder : encoders) encoder->finish();
  durations["render_and_encode"] = secondsSince(stage) - groundTruthS;
  durations["ground_truth"] = groundTruthS;

  std::vector<daemon::RigCamera> rig;
  for (const auto& camera : plan.cameras) {
    daemon::RigCamera entry = camera.camera;
    capture::FileSourceSettings source;
    source.path = folder.path() / (entry.calibration.name + ".mkv");
    entry.source = source;
    rig.push_back(std::move(entry));
  }
  daemon::writeRigFile(folder.path() / "rig.yaml", rig,
                       fmt::format("Written by surround-synth from {} (seed {}): the exact "
                                   "calibration of the cameras that rendered these videos.",
                                   options.rig.filename().string(), options.seed),
                       plan.vehicle ? &*plan.vehicle : nullptr);
  writeGroundTruthYaml(folder.path() / "ground_truth.yaml", plan, framesWritten);
  durations["total"] = secondsSince(start);
  writeManifest(folder.path() / "manifest.yaml", plan, durations);
  folder.publish(outAbsolute);

  result.seconds = secondsSince(start);
  log << fmt::format(
             "wrote {}: {} cameras x {} frames of {}x{} in {:.1f} s (scene {:.2f} s, rays {:.2f} "
             "s, render+encode {:.1f} s, ground truth {:.1f} s)",
             options.out.string(), plan.cameras.size(), plan.frames,
             plan.cameras.front().camera.calibration.intrinsics.imageSize.width,
             plan.cameras.front().camera.calibration.intrinsics.imageSize.height, result.seconds,
             durations["scene"], durations["rays"], durations["render_and_encode"], groundTruthS)
      << std::endl;
  return result;
}

}  // namespace surroundd::synth
