#include "tools/calibrate/guide/guide_options.hpp"

#include <charconv>

#include <fmt/format.h>

#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {

const std::string_view kGuideUsage =
    R"(usage: surround-calibrate guide (--device DEV | --file PATH) (--board COLSxROWS |
                             --charuco COLSxROWS) --model pinhole|fisheye --out FILE [options]

A guided intrinsics calibration of one camera on a web page: the camera live with the board it
finds drawn in, each view it keeps listed and outlined, the coverage map filling up, and what is
still missing in words ("tilt the board into the top left corner"). A view is kept when the board
is found, sharp (--max-edge-width-px) and not where a kept view already is. Once --min-views views
and --min-coverage are there, each new view solves again; the verdict is shown, and on a pass the
lens: block is written (the same as surround-calibrate intrinsics --out) and the page says so. A
failed solve writes nothing: the page says why and keeps collecting. Stop with Ctrl-C; the exit
status is 0 when the lens passed and was written, 1 otherwise.

  --device DEV               a V4L2 camera (/dev/video0, /dev/v4l/by-id/...)
  --size WxH                 with --device: the picture size to ask for (default 1280x720)
  --fps F                    with --device: the frame rate to ask for; with --file: a picture
                             sequence's rate (default 30)
  --file PATH                a video, a picture sequence (frame_%04d.png) or one picture, replayed
                             at its own pace (a recording of a session, surround-synth
                             --calibration-session); it waits after its first frame until
                             the page is open, so that the page shows the session from its start
  --loop                     with --file: start again at the end
  --listen ADDR:PORT         where to serve the page (default 127.0.0.1:8080; port 0: any free
                             one; the address is printed)
  --password-file FILE       who may see the page: USER:PASSWORD on the file's first line (chmod
                             600), asked by HTTP basic authentication; required when --listen is
                             not 127.x.x.x
  --board, --charuco, --dictionary, --marker-ratio, --model, --out, --square, --field-of-view-deg,
  --update-rig, --camera and the limits (--max-rms-px, --max-view-rms-px, --max-edge-width-px,
  --min-coverage, --min-views): as for surround-calibrate intrinsics

The page (GET /) reads GET /state.json (views, coverage cells, hints, verdict, files written)
and shows GET /stream.mjpg.
)";

namespace {

cv::Size parseFrameSize(std::string_view text) {
  int w = 0, h = 0;
  const auto x = text.find('x');
  const auto a = std::from_chars(text.data(), text.data() + std::min(x, text.size()), w);
  if (x == std::string_view::npos || a.ptr != text.data() + x ||
      std::from_chars(text.data() + x + 1, text.data() + text.size(), h).ptr !=
          text.data() + text.size() ||
      w < 16 || h < 16 || w > 8192 || h > 8192) {
    throw UsageError(fmt::format("--size: expected WxH (e.g. 1280x720), got '{}'", text));
  }
  return {w, h};
}

void parseListen(std::string_view text, std::string& address, int& port) {
  const auto colon = text.rfind(':');
  if (colon == std::string_view::npos || colon == 0) {
    throw UsageError(
        fmt::format("--listen: expected ADDRESS:PORT (e.g. 127.0.0.1:8080), got '{}'", text));
  }
  address = std::string(text.substr(0, colon));
  port = static_cast<int>(
      parseDouble("--listen", text.substr(colon + 1), 0, 65535, "a port from 0 to 65535"));
}

}  // namespace

Handlers cameraAndPageHandlers(cv::Size& size, bool& sizeGiven, double& fps, std::string& address,
                               int& port, std::optional<std::filesystem::path>& passwordFile) {
  return {{"--size",
           [&](auto v) {
             size = parseFrameSize(v);
             sizeGiven = true;
           }},
          {"--fps",
           [&](auto v) {
             fps = parseDouble("--fps", v, 0.1, 1000, "frames per second from 0.1 to 1000");
           }},
          {"--listen", [&](auto v) { parseListen(v, address, port); }},
          {"--password-file", [&](auto v) { passwordFile = std::string(v); }}};
}

std::optional<render::Credentials> pageCredentials(
    const std::string& address, const std::optional<std::filesystem::path>& passwordFile) {
  if (passwordFile) {
    try {
      return render::readCredentialsFile(*passwordFile);
    } catch (const std::runtime_error& error) {
      throw UsageError(fmt::format("--password-file: {}", error.what()));
    }
  }
  if (!render::isLoopbackAddress(address)) {
    throw UsageError(fmt::format(
        "--listen: {} is beyond this machine: give --password-file FILE (USER:PASSWORD, chmod "
        "600) so that only those who have it see the cameras, or listen on 127.0.0.1",
        address));
  }
  return std::nullopt;
}

GuideOptions parseGuide(std::span<const std::string_view> arguments) {
  GuideOptions o;
  bool size = false;
  std::optional<std::filesystem::path> passwordFile;
  Handlers valued = cameraAndPageHandlers(o.size, size, o.fps, o.address, o.port, passwordFile);
  valued.merge(Handlers{{"--device", [&](auto v) { o.device = std::string(v); }},
                        {"--file", [&](auto v) { o.file = std::string(v); }}});
  o.lens = parseLensOptions(arguments, std::move(valued),
                            {{"--loop", [&](auto) { o.loop = true; }}}, false);
  if (o.device.has_value() == o.file.has_value()) {
    throw UsageError("--device or --file: give one camera (a V4L2 device, or a recording)");
  }
  if (o.device && o.loop) throw UsageError("--loop: only a --file loops");
  if (o.file && size) throw UsageError("--size: only a --device takes it (a file has its size)");
  o.credentials = pageCredentials(o.address, passwordFile);
  return o;
}

}  // namespace surroundd::calibrate
