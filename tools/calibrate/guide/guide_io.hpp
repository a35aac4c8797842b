#pragma once
// The two ends of a guided calibration (surround-calibrate guide, with or without --mat): a
// camera to read, live or a recording replayed at its own pace, and the page served beside the
// picture stream.

#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <opencv2/core.hpp>

#include "capture/frame_source.hpp"
#include "render/outputs/http_stream_sink.hpp"

namespace surroundd::calibrate {

struct GuideCameraSource {
  // One of the two: a V4L2 device, or a video / picture sequence / picture.
  std::optional<std::filesystem::path> device;
  std::optional<std::filesystem::path> file;
  cv::Size size{1280, 720};  // device: the size to ask for
  double fps = 30;           // device: the rate to ask for; file: a picture sequence's rate
  bool loop = false;         // file: start again at its end
};

// Throws UsageError "OPTION: why" when it cannot be opened; `option` names where it was given.
std::unique_ptr<capture::FrameSource> openGuideCamera(const std::string& name,
                                                      const GuideCameraSource& source,
                                                      std::string_view option);

// Serves `page` at "/" with the picture stream and GET /state.json (setStatus()). Throws
// UsageError for a bad --listen, std::runtime_error when it cannot listen.
std::unique_ptr<render::HttpStreamSink> serveGuidePage(
    const std::string& address, int port, const std::optional<render::Credentials>& credentials,
    std::string_view page);

// SIGINT and SIGTERM (Ctrl-C, systemctl stop) end a guide: from this call on they set the flag
// that stopRequested() reads.
void stopOnSignals();
bool stopRequested();
// A camera's backoff before it is opened again (capture::SourceRecovery::Wait): sleeps for
// `duration`, cut short by a stop; false when the guide is stopping.
bool waitUnlessStopped(std::chrono::milliseconds duration);

// A recording is a session to watch: after its first frame it waits for the page to open (its
// picture stream to be asked for: HttpStreamSink then wants frames again), so that the page sees
// the session from its start. Returns early on a stop.
void waitForPage(const render::HttpStreamSink& page);

// After the stream: the page keeps showing the result until the user stops it.
void waitForStop();

}  // namespace surroundd::calibrate
