#include "tools/calibrate/guide/guide_command.hpp"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "capture/source_recovery.hpp"
#include "processing/calibration/calibration_error.hpp"
#include "render/outputs/http_stream_sink.hpp"
#include "tools/calibrate/calibrate_options.hpp"
#include "tools/calibrate/calibration_output.hpp"
#include "tools/calibrate/guide/guide_io.hpp"
#include "tools/calibrate/guide/guide_page.hpp"
#include "tools/calibrate/guide/guide_session.hpp"
#include "tools/calibrate/guide/guide_state_json.hpp"

namespace surroundd::calibrate {
namespace {

// The frame as the page shows it: kept views' outlines thin, the board found now with its corners
// (green when kept, amber when not).
void drawFrame(cv::Mat& bgr, const GuideSession& session, const FrameResult& result) {
  for (const auto& view : session.views()) {
    std::vector<cv::Point> hull;
    std::vector<cv::Point> points(view.view.corners.begin(), view.view.corners.end());
    cv::convexHull(points, hull);
    cv::polylines(bgr, hull, true, cv::Scalar(90, 160, 90), 1, cv::LINE_AA);
  }
  const cv::Scalar colour =
      result.outcome == FrameOutcome::kAccepted ? cv::Scalar(60, 220, 60) : cv::Scalar(0, 190, 255);
  for (const auto& corner : result.corners) {
    cv::circle(bgr, corner, 3, colour, 1, cv::LINE_AA);
  }
}

std::string sourceName(const GuideOptions& options) {
  return options.device ? options.device->string() : options.file->string();
}

// Writes the passed lens (and the rig's camera); the files written, or throws.
std::vector<std::string> writeLens(const GuideOptions& options, const GuideSession& session) {
  const auto& solve = *session.lastSolve();
  const std::string comment = fmt::format(
      "Written by surround-calibrate guide from {} of {} views of {} ({}):\n"
      "RMS reprojection error {:.3f} px; passed after {:.1f} s of stream.",
      solve.result.views.size(), session.views().size(), sourceName(options),
      options.lens.board.describe(), solve.result.rmsPx,
      std::chrono::duration<double>(session.passedAt()).count());
  writeLensBlock(options.lens.out, solve.result.intrinsics, comment);
  std::vector<std::string> written{options.lens.out.string()};
  if (options.lens.updateRig) {
    updateRigLens(*options.lens.updateRig, options.lens.camera, solve.result.intrinsics, comment);
    written.push_back(options.lens.updateRig->string());
  }
  return written;
}

}  // namespace

void runGuide(const GuideOptions& options, std::ostream& log) {
  if (options.lens.updateRig) rigCamera(*options.lens.updateRig, options.lens.camera);
  auto camera = openGuideCamera(
      "guide", {options.device, options.file, options.size, options.fps, options.loop},
      options.device ? "--device" : "--file");
  GuideSettings settings;
  settings.board = options.lens.board;
  settings.model = options.lens.model;
  settings.limits = options.lens.limits;
  settings.fieldOfViewDeg = options.lens.fieldOfViewDeg;
  GuideSession session(settings);
  GuideRunState run;

  const auto served =
      serveGuidePage(options.address, options.port, options.credentials, guidePage());
  render::HttpStreamSink& page = *served;
  page.setStatus(guideStateJson(session, run));
  log << fmt::format("guide page: http://{}:{}/ (reading {}; Ctrl-C stops)\n", options.address,
                     page.port(), sourceName(options))
      << std::flush;

  stopOnSignals();
  capture::Frame frame;
  frame.image = cv::Mat(camera->frameSize(), CV_8UC3);
  cv::Mat gray;
  std::optional<capture::Timestamp> start;
  bool written = false;
  // The daemon's policy for every camera: faults counted and logged with rate limiting, a lost
  // device reopened with backoff, for as long as the guide runs.
  capture::SourceRecovery recovery("guide", {});
  while (!stopRequested() && !run.ended) {
    const auto status = recovery.read(*camera, frame, waitUnlessStopped);
    if (status == capture::ReadStatus::kEndOfStream) {
      run.ended = true;
    } else if (status == capture::ReadStatus::kFault) {
      run.error = fmt::format("{}: {}", sourceName(options), camera->lastError());
    } else {
      run.error.clear();
      if (!start) start = frame.timestamp;
      run.streamTime = frame.timestamp - *start;
      cv::cvtColor(frame.image, gray, cv::COLOR_BGR2GRAY);
      const std::size_t kept = session.views().size();
      run.last = session.offer(gray, run.streamTime);
      if (session.views().size() > kept) {
        log << fmt::format("{:7.2f} s  {}\n", std::chrono::duration<double>(run.streamTime).count(),
                           run.last.note);
        if (const auto& solve = session.lastSolve(); solve && solve->viewsOffered == kept + 1) {
          log << fmt::format(
              "          solved with {} views: {}\n", solve->viewsOffered,
              solve->verdict.passed
                  ? fmt::format("pass, RMS {:.3f} px", solve->result.rmsPx)
                  : fmt::format("fail ({})", fmt::join(solve->verdict.failures, "; ")));
        }
      }
      if (session.passed() && !written) {
        written = true;
        try {
          run.written = writeLens(options, session);
          for (const auto& file : run.written) log << "wrote " << file << "\n";
        } catch (const std::exception& error) {
          run.error = fmt::format("cannot write the lens: {}", error.what());
          log << run.error << "\n";
        }
      }
      drawFrame(frame.image, session, run.last);
      page.consume(frame.image, run.streamTime);
      if (options.file && session.framesOffered() == 1) waitForPage(page);
    }
    page.setStatus(guideStateJson(session, run));
    log << std::flush;
  }
  if (run.ended) log << "the recording ended; the page stays up until Ctrl-C\n" << std::flush;
  waitForStop();
  page.finish({}, run.streamTime);
  if (!session.passed() || run.written.empty()) {
    throw processing::CalibrationError(
        session.passed() ? run.error
                         : fmt::format("stopped before the lens passed ({} views kept); nothing "
                                       "was written",
                                       session.views().size()));
  }
}

}  // namespace surroundd::calibrate
