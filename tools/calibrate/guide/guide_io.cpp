#include "tools/calibrate/guide/guide_io.hpp"

#include <algorithm>
#include <atomic>
#include <csignal>
#include <thread>

#include <fmt/format.h>

#include "capture/file_source.hpp"
#include "capture/v4l2_source.hpp"
#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {
namespace {

std::atomic<bool> stopFlag{false};
extern "C" void onStopSignal(int /*signal*/) { stopFlag = true; }

}  // namespace

std::unique_ptr<capture::FrameSource> openGuideCamera(const std::string& name,
                                                      const GuideCameraSource& source,
                                                      std::string_view option) {
  try {
    if (source.device) {
      capture::V4l2Settings settings;
      settings.device = *source.device;
      settings.size = source.size;
      settings.fps = source.fps;
      return std::make_unique<capture::V4l2Source>(name, settings);
    }
    return std::make_unique<capture::FileSource>(
        name, capture::FileSourceSettings{*source.file, source.fps, source.loop,
                                          capture::Pacing::kRealtime});
  } catch (const capture::CaptureError& error) {
    throw UsageError(fmt::format("{}: {}", option, error.what()));
  }
}

std::unique_ptr<render::HttpStreamSink> serveGuidePage(
    const std::string& address, int port, const std::optional<render::Credentials>& credentials,
    std::string_view page) {
  render::HttpStreamSettings http;
  http.address = address;
  http.port = port;
  http.credentials = credentials;
  http.page = page;
  http.statusPath = "/state.json";
  try {
    http.validate();
  } catch (const std::invalid_argument& error) {
    throw UsageError(fmt::format("--listen: {}", error.what()));
  }
  return std::make_unique<render::HttpStreamSink>(http);
}

void stopOnSignals() {
  std::signal(SIGINT, onStopSignal);
  std::signal(SIGTERM, onStopSignal);
}

bool stopRequested() { return stopFlag; }

bool waitUnlessStopped(std::chrono::milliseconds duration) {
  const auto until = std::chrono::steady_clock::now() + duration;
  while (!stopFlag && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::min(duration, std::chrono::milliseconds(50)));
  }
  return !stopFlag;
}

// Polls: the sink has no call that waits.
void waitForPage(const render::HttpStreamSink& page) {
  while (!stopFlag && !page.wantsFrame({})) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

// A poll, not a synchronisation: nothing waits on anything but the signal.
void waitForStop() {
  while (!stopFlag) std::this_thread::sleep_for(std::chrono::milliseconds(100));
}

}  // namespace surroundd::calibrate
