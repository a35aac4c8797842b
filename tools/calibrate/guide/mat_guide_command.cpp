#include "tools/calibrate/guide/mat_guide_command.hpp"

#include <algorithm>
#include <chrono>
#include <memory>
#include <thread>

#include <fmt/format.h>

#include "capture/source_recovery.hpp"
#include "processing/calibration/calibration_error.hpp"
#include "tools/calibrate/calibrate_options.hpp"
#include "tools/calibrate/camera_pictures.hpp"
#include "tools/calibrate/extrinsics/mat_command.hpp"
#include "tools/calibrate/extrinsics/mat_mounts_output.hpp"
#include "tools/calibrate/extrinsics/mat_report.hpp"
#include "tools/calibrate/guide/guide_io.hpp"
#include "tools/calibrate/guide/mat_guide_page.hpp"
#include "tools/calibrate/guide/mat_guide_session.hpp"
#include "tools/calibrate/guide/mat_guide_state_json.hpp"
#include "tools/calibrate/guide/mat_guide_view.hpp"
#include "tools/calibrate/marker_file.hpp"

namespace surroundd::calibrate {
namespace {

struct Camera {
  std::string source;  // the device or file, for messages
  std::unique_ptr<capture::FrameSource> stream;
  capture::Frame frame;
  bool ended = false;
  // The daemon's policy, as for guide without --mat: faults counted and logged with rate
  // limiting, a lost device reopened with backoff.
  std::unique_ptr<capture::SourceRecovery> recovery;
};

// Each camera's source: its --device, else its picture in --images, read once (a still picture
// does not change: one solve is all it can give).
std::vector<Camera> openCameras(const MatGuideOptions& options,
                                const std::vector<processing::CameraCalibration>& nominal) {
  for (const auto& device : options.devices) {
    const std::string& name = device.first;
    if (std::none_of(nominal.begin(), nominal.end(),
                     [&](const auto& c) { return c.name == name; })) {
      throw UsageError(fmt::format("--device {}={}: the mat {} names no camera '{}'", name,
                                   device.second.string(), options.mat.string(), name));
    }
  }
  std::vector<Camera> cameras;
  cameras.reserve(nominal.size());
  for (const auto& calibration : nominal) {
    const auto device = std::find_if(options.devices.begin(), options.devices.end(),
                                     [&](const auto& d) { return d.first == calibration.name; });
    Camera camera;
    GuideCameraSource source;
    std::string option;
    if (device != options.devices.end()) {
      source.device = device->second;
      source.size = options.size;
      source.fps = options.fps;
      option = fmt::format("--device {}", calibration.name);
    } else if (options.images) {
      source.file = requirePicture(*options.images, calibration.name);
      option = "--images";
    } else {
      throw UsageError(
          fmt::format("--device: camera '{}' has no source (give --device {}=DEV, or --images)",
                      calibration.name, calibration.name));
    }
    camera.source = (source.device ? *source.device : *source.file).string();
    camera.stream = openGuideCamera(calibration.name, source, option);
    checkPictureSize(camera.source, camera.stream->frameSize(), calibration, options.rig);
    camera.frame.image = cv::Mat(camera.stream->frameSize(), CV_8UC3);
    camera.recovery =
        std::make_unique<capture::SourceRecovery>(calibration.name, capture::RecoverySettings{});
    cameras.push_back(std::move(camera));
  }
  return cameras;
}

// Reads one frame of `camera` into the session; true when that solved.
bool readInto(Camera& camera, std::size_t index, MatGuideSession& session, MatGuideRunState& run) {
  const auto status = camera.recovery->read(*camera.stream, camera.frame, waitUnlessStopped);
  if (status == capture::ReadStatus::kEndOfStream) {
    camera.ended = true;
    return false;
  }
  if (status == capture::ReadStatus::kFault) {
    run.error = fmt::format("{}: {}", camera.source, camera.stream->lastError());
    return false;
  }
  return session.offer(index, camera.frame.image);
}

// After each solve: the table in the log, and the mounts written when it passed. A failed
// verdict is refused by writeMatMounts, which writes nothing; its message goes to the page.
void afterSolve(const MatGuideOptions& options, const MatGuideSession& session,
                MatGuideRunState& run, std::ostream& log) {
  const auto& result = *session.result();
  log << fmt::format("solve {}:\n", session.solves());
  printMatReport(session.settings().mat, result, log);
  MatMountTargets targets{options.out, options.rig};
  const std::string comment = fmt::format(
      "Written by surround-calibrate guide --mat from the mat {}: every camera and seam passed "
      "(seam limit {:g} cm).",
      options.mat.string(), session.settings().limits.maxSeamCm);
  try {
    run.written = writeMatMounts(result, targets, comment, "see the page");
    run.error.clear();
    for (const auto& file : run.written) log << "wrote " << file << "\n";
  } catch (const processing::CalibrationError& refused) {
    run.error = fmt::format("the verdict failed: {}", refused.what());
    log << run.error << "\n";
  } catch (const std::exception& error) {
    run.error = fmt::format("cannot write the mounts: {}", error.what());
    log << run.error << "\n";
  }
}

}  // namespace

void runMatGuide(const MatGuideOptions& options, std::ostream& log) {
  MatGuideSettings settings;
  settings.mat = loadMatFile(options.mat);
  settings.cameras = matCameras(options.rig, options.mat, settings.mat);
  settings.limits = options.limits;
  settings.solve.inlierThresholdPx = options.inlierPx;
  auto cameras = openCameras(options, settings.cameras);
  MatGuideSession session(std::move(settings));
  MatGuideRunState run;

  const auto served =
      serveGuidePage(options.address, options.port, options.credentials, matGuidePage());
  render::HttpStreamSink& page = *served;
  page.setStatus(matGuideStateJson(session, run));
  log << fmt::format("guide page: http://{}:{}/ (reading {} cameras; Ctrl-C stops)\n",
                     options.address, page.port(), cameras.size())
      << std::flush;

  stopOnSignals();
  const auto start = std::chrono::steady_clock::now();
  const auto sinceStart = [&] { return std::chrono::steady_clock::now() - start; };
  cv::Mat shown = matGuideFrame(session);
  // One thread reads the cameras in turn: the mat lies still, so a round of pictures need not
  // be simultaneous, only each camera's newest.
  while (!stopRequested() && !run.ended) {
    for (std::size_t c = 0; c < cameras.size() && !stopRequested(); ++c) {
      if (cameras[c].ended) continue;
      if (readInto(cameras[c], c, session, run)) afterSolve(options, session, run, log);
    }
    run.ended = std::all_of(cameras.begin(), cameras.end(), [](const auto& c) { return c.ended; });
    shown = matGuideFrame(session);
    page.consume(shown, sinceStart());
    page.setStatus(matGuideStateJson(session, run));
    log << std::flush;
  }
  if (run.ended) log << "the pictures ended; the page stays up until Ctrl-C\n" << std::flush;
  // The page keeps showing the result until the user stops it: a client that opens it later
  // gets the last picture. A poll: the sink has no call that waits.
  while (!stopRequested()) {
    if (page.wantsFrame(sinceStart())) page.consume(shown, sinceStart());
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  page.finish({}, sinceStart());
  if (!session.passed() || run.written.empty()) {
    throw processing::CalibrationError(
        session.passed() ? run.error
                         : fmt::format("stopped before every camera and seam passed ({}); nothing "
                                       "was written",
                                       run.error.empty() ? "no solve" : run.error));
  }
}

}  // namespace surroundd::calibrate
