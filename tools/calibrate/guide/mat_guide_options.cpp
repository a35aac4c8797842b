#include "tools/calibrate/guide/mat_guide_options.hpp"

#include <fmt/format.h>

#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {

const std::string_view kMatGuideUsage =
    R"(usage: surround-calibrate guide --mat FILE --rig FILE (--images DIR | --device NAME=DEV...)
                             [options]

With --mat, the guided extrinsics calibration of every camera of a rig on a calibration mat
(checkerboards of known size and place on the ground around the car, see
config/mats/four-corner-mat.yaml) on a web page: each camera's picture with the boards it found,
a table per camera (boards found, corners, reprojection RMS, change from the rig's mount), and,
once every camera has a picture, each camera's mount solved (as surround-calibrate extrinsics
--mat), the ground stitched through the solved mounts as a top view with the boards where the
layout puts them, and the seam error in centimetres on every board two neighbouring cameras
share, each against --max-seam-cm. The verdict passes when every camera and every seam passes;
then every camera's mount is written into --rig at once (the file is replaced whole: all the
mounts or none) and the page names it. A failed verdict writes nothing: the page and the log say
what failed, and a live rig solves again with each new round of pictures. Stop with Ctrl-C; the
exit status is 0 when the mounts passed and were written, 1 otherwise.

  --mat FILE                 the mat's layout (YAML; see tools/calibrate/marker_file.hpp)
  --rig FILE                 the rig: each camera's lens, and its mount as measured so far (it
                             tells boards of one pattern apart); the solved mounts replace them
                             on a pass
  --images DIR               one picture per camera, named after it (front.png, left.jpg, ...;
                             surround-synth --calibration-mat writes such a folder)
  --device NAME=DEV          camera NAME live from a V4L2 device (repeat per camera; a camera
                             without one reads its picture from --images)
  --size WxH                 with --device: the picture size to ask for (default 1280x720)
  --fps F                    with --device: the frame rate to ask for (default 30)
  --out FILE                 also write the mount: blocks to FILE (as extrinsics --out)
  --listen ADDR:PORT         where to serve the page (default 127.0.0.1:8080; port 0: any free
                             one; the address is printed)
  --password-file FILE       who may see the page: USER:PASSWORD on the file's first line (chmod
                             600), asked by HTTP basic authentication; required when --listen is
                             not 127.x.x.x
  --inlier-px, --min-corners, --max-rms-px, --max-shift-m, --max-turn-deg, --max-seam-cm: as for
                             surround-calibrate extrinsics --mat (the seam limit, default 3 cm,
                             is the threshold the page states)

The page (GET /) reads GET /state.json (cameras, seams, verdict, files written) and shows
GET /stream.mjpg (the cameras and the stitched top view).
)";

MatGuideOptions parseMatGuide(std::span<const std::string_view> arguments) {
  MatGuideOptions o;
  bool size = false;
  Handlers valued = matLimitHandlers(o.limits, o.inlierPx);
  std::optional<std::filesystem::path> passwordFile;
  valued.merge(cameraAndPageHandlers(o.size, size, o.fps, o.address, o.port, passwordFile));
  valued.merge(
      Handlers{{"--mat", [&](auto v) { o.mat = std::string(v); }},
               {"--rig", [&](auto v) { o.rig = std::string(v); }},
               {"--images", [&](auto v) { o.images = std::string(v); }},
               {"--out", [&](auto v) { o.out = std::string(v); }},
               {"--device", [&](std::string_view v) {
                  const auto equals = v.find('=');
                  if (equals == std::string_view::npos || equals == 0 || equals + 1 == v.size()) {
                    throw UsageError(fmt::format(
                        "--device: expected NAME=DEVICE (e.g. front=/dev/video0), got '{}'", v));
                  }
                  o.devices.emplace_back(std::string(v.substr(0, equals)),
                                         std::string(v.substr(equals + 1)));
                }}});
  parseOptions(arguments, valued, {});
  if (o.mat.empty()) throw UsageError("--mat: missing (the mat's layout)");
  if (o.rig.empty()) {
    throw UsageError("--rig: missing (the rig file with the cameras' lenses and mounts)");
  }
  if (!o.images && o.devices.empty()) {
    throw UsageError(
        "--images or --device: missing (a folder with one picture per camera, or each camera "
        "live)");
  }
  if (size && o.devices.empty()) throw UsageError("--size: only a --device takes it");
  o.credentials = pageCredentials(o.address, passwordFile);
  return o;
}

}  // namespace surroundd::calibrate
