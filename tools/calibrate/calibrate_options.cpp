#include "tools/calibrate/calibrate_options.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "common/build_info.hpp"

namespace surroundd::calibrate {
namespace {

constexpr std::string_view kExtrinsicsUsage =
    R"(usage: surround-calibrate extrinsics --rig FILE --camera NAME --image FILE
                                  (--markers FILE | --points FILE)... --out FILE [options]
       surround-calibrate extrinsics --rig FILE --mat FILE --images DIR --out FILE [options]

The pose of one camera on the vehicle from ground markers (checkerboards, ArUco) at known
vehicle-frame positions, or from listed points with their pixels. Prints the reprojection error
and the change from the rig's current mount; writes the camera's mount: block.

  --rig FILE                 rig file with the camera's lens (and its current mount, used to tell
                             boards of one pattern apart)
  --camera NAME              the camera in the rig
  --image FILE               the camera's image of the markers
  --markers FILE             ground markers (YAML; see tools/calibrate/marker_file.hpp)
  --points FILE              points with known pixels in this camera's image (YAML), at least
                             6, spread over the image, not all on one line:
                               points:
                                 - {name: pole_base, x_m: 4.0, y_m: 0.5, z_m: 0,
                                    u_px: 612.4, v_px: 388.1}
                             x_m y_m z_m: the point in the vehicle frame (x forward, y left,
                             z up; z_m defaults to 0, the ground); u_px v_px: its pixel (column,
                             row; pixel centres at whole numbers); name: used in messages
  --out FILE                 the mount: block (YAML)
  --residuals FILE           a PNG of the image with each point's residual magnified
  --inlier-px X              points missing by more are outliers (default 3)
  --update-rig               also write the mount into the rig file (see "--update-rig" below)

With --mat, every camera the mat names at once, from one picture each of a calibration mat:
checkerboards of known size and place on the ground, each seen by one camera or by two
neighbours (see config/mats/four-corner-mat.yaml). Prints a table per camera (boards found,
corners, reprojection RMS, change from the rig) and the seam error on the ground between cameras
that share a board; writes only when every camera and seam passes, and exits 1 otherwise.

  --mat FILE                 the mat's layout (YAML; see tools/calibrate/marker_file.hpp)
  --images DIR               one picture per camera, named after it (front.png, left.jpg, ...)
  --out FILE                 every camera's mount: block, under cameras: (YAML)
  --min-corners N            per camera (default 20)
  --max-rms-px X             reprojection RMS per camera (default 1)
  --max-shift-m M            solved position against the rig's mount (default 0.5)
  --max-turn-deg D           solved rotation against the rig's mount (default 15)
  --max-seam-cm C            RMS ground distance of a shared board's corners (default 3)
  --inlier-px X, --update-rig  as above
)";

constexpr std::string_view kMaskUsage =
    R"(usage: surround-calibrate mask --config FILE --out DIR [--camera NAME]
       surround-calibrate mask --from RECORDING --out DIR [--camera NAME] [--every S]

Each camera's body mask (the pixels that see the vehicle, left out of the panorama and colour
correction) drawn on the camera's first picture, to check it, and the mask itself, to edit it. The
mask is what surroundd uses: computed from the config's vehicle: block (or the rig's), then the
camera's body_mask: added or put in its place. Writes, per camera:

  DIR/NAME-mask-overlay.png  the picture with the masked pixels tinted red and outlined, labelled
                             with the masked share and where the mask came from (a live camera's
                             picture is grey: no frame is read from a device)
  DIR/NAME-body.png          the mask, white = body: edit it in any paint program and give it back
                             as the camera's body_mask: {file: NAME-body.png, mode: replace}

  --config FILE              the surroundd config
  --out DIR                  folder for the pictures (made when missing)
  --camera NAME              only this camera

With --from, the body is found in a recording of a drive instead (a surroundd recording output's
folder, or a rig file whose cameras are recordings): where a camera looks down at the road, what
keeps its place while the ground slides past is its own car — a bumper, the grille, a mirror's
housing, the roof — which no measured box may fit. Record a drive of at least ten seconds (a few
metres, turning a little, in daylight). Writes, per camera:

  DIR/NAME-found-body.png     the body found, white = body
  DIR/NAME-found-overlay.png  the drive's last picture with it tinted red

and prints each camera's body_mask: with the outlines as polygons (mode: add, so that the mask
computed from vehicle: stays: a body that mirrors the road at a grazing angle, a glossy flank,
shows no still picture and is only found there).

  --from RECORDING           the recording's rig file, or its folder (with rig.yaml)
  --every S                  seconds of the drive between the pictures compared (default 0.5)
)";

constexpr std::string_view kRefineUsage =
    R"(usage: surround-calibrate refine (--config FILE | --rig RIG) --out DIR [--images DIR]
                                 [--every S] [--update-rig]

The cameras' mounts corrected from the road: where two neighbouring cameras see the same ground,
a mount that is off puts it elsewhere. Patches of the ground both see are compared set after set
(the car driving over ground with some texture: asphalt grain, lines, kerbs, gravel), and each
camera is turned (and raised) so that the ground meets under every seam; the camera that needs no
turning is held. Three passes, each through the last one's corrections. Prints each camera's
correction in mount angles with its uncertainty, and each seam's misalignment before and after;
a correction too uncertain to act on (the cameras share too little ground near the car, or it
has no texture), or under 0.2 degrees, is said and left out. Writes:

  DIR/mounts.yaml        the refined cameras' mount: blocks, to paste into the rig
  DIR/top-before.png     the ground from above through the mounts given (doubled where off)
  DIR/top-after.png      the same through the refined mounts

  --config FILE          a surroundd config: its rig file, vehicle and body masks (mask the
                         body: ground that keeps still under a seam pulls the fit)
  --rig RIG              or a rig file, or a recording's folder (with rig.yaml)
  --images DIR           one still picture per camera, named after it (front.png, Back.jpg...);
                         without it, the cameras' recorded sources, read side by side
  --every S              seconds of a recording between the sets compared (default 0.5; at most
                         240 sets)
  --update-rig           write the refined mounts into the rig file (the file before is kept
                         beside it as FILE.before-refine)
)";

constexpr std::string_view kUpdateRigUsage =
    R"(--update-rig edits the rig file's YAML: only the camera's lens: (intrinsics) or mount:
(extrinsics) block is replaced. Every other key stays as it was (sources with their sequence_fps,
health, roles, the other cameras), and so does the comment block at the head of the file. Comments
inside the document are lost (the YAML library keeps none); a one-line note beside the new block
says where it came from. The result must read back to the new calibration, or the rig is left as
it was and the command fails.
)";

ExtrinsicsOptions parseExtrinsics(std::span<const std::string_view> arguments) {
  ExtrinsicsOptions o;
  Handlers valued = matLimitHandlers(o.limits, o.inlierPx);
  valued.merge(Handlers{{"--rig", [&](auto v) { o.rig = std::string(v); }},
                        {"--camera", [&](auto v) { o.camera = std::string(v); }},
                        {"--image", [&](auto v) { o.image = std::string(v); }},
                        {"--markers", [&](auto v) { o.markers = std::string(v); }},
                        {"--points", [&](auto v) { o.points = std::string(v); }},
                        {"--out", [&](auto v) { o.out = std::string(v); }},
                        {"--residuals", [&](auto v) { o.residuals = std::string(v); }},
                        {"--mat", [&](auto v) { o.mat = std::string(v); }},
                        {"--images", [&](auto v) { o.images = std::string(v); }}});
  parseOptions(arguments, valued, {{"--update-rig", [&](auto) { o.updateRig = true; }}});
  if (o.rig.empty()) throw UsageError("--rig: missing (the rig file with the camera's lens)");
  if (o.mat) {
    if (!o.camera.empty() || !o.image.empty() || o.markers || o.points || o.residuals) {
      throw UsageError(
          "--mat: calibrates every camera the mat names from --images; --camera, "
          "--image, --markers, --points and --residuals do not go with it");
    }
    if (!o.images) throw UsageError("--images: missing (the folder with one picture per camera)");
    if (o.out.empty()) throw UsageError("--out: missing (the file to write the mount: blocks to)");
    return o;
  }
  if (o.images) throw UsageError("--images: only with --mat (one picture per camera of a mat)");
  if (o.camera.empty()) throw UsageError("--camera: missing (the camera in the rig to calibrate)");
  if (o.image.empty()) throw UsageError("--image: missing (the camera's image of the markers)");
  if (!o.markers && !o.points) {
    throw UsageError("--markers or --points: missing (what the camera sees, and where it is)");
  }
  if (o.out.empty()) throw UsageError("--out: missing (the file to write the mount: block to)");
  return o;
}

MaskOptions parseMask(std::span<const std::string_view> arguments) {
  MaskOptions o;
  parseOptions(
      arguments,
      {{"--config", [&](auto v) { o.config = std::string(v); }},
       {"--from", [&](auto v) { o.from = std::string(v); }},
       {"--every", [&](auto v) { o.everyS = parseDouble("--every", v, 0.02, 60, "seconds"); }},
       {"--out", [&](auto v) { o.out = std::string(v); }},
       {"--camera", [&](auto v) { o.camera = std::string(v); }}},
      {});
  if (o.config.empty() == o.from.empty()) {
    throw UsageError(
        "expected either --config (the surroundd config: its masks drawn) or --from (a recording "
        "of a drive: the body found in it)");
  }
  if (o.out.empty()) throw UsageError("--out: missing (the folder to write the pictures to)");
  return o;
}

RefineOptions parseRefine(std::span<const std::string_view> arguments) {
  RefineOptions o;
  parseOptions(
      arguments,
      {{"--config", [&](auto v) { o.config = std::string(v); }},
       {"--rig", [&](auto v) { o.rig = std::string(v); }},
       {"--images", [&](auto v) { o.images = std::string(v); }},
       {"--every", [&](auto v) { o.everyS = parseDouble("--every", v, 0.02, 60, "seconds"); }},
       {"--out", [&](auto v) { o.out = std::string(v); }}},
      {{"--update-rig", [&](auto) { o.updateRig = true; }}});
  if (o.config.empty() == o.rig.empty()) {
    throw UsageError(
        "expected either --config (a surroundd config) or --rig (a rig file or a recording's "
        "folder)");
  }
  if (o.out.empty()) throw UsageError("--out: missing (the folder to write mounts.yaml to)");
  return o;
}

bool asksForHelp(std::span<const std::string_view> arguments) {
  return std::any_of(arguments.begin(), arguments.end(),
                     [](auto a) { return a == "--help" || a == "-h"; });
}

}  // namespace

Handlers matLimitHandlers(processing::MatLimits& limits, double& inlierPx) {
  return {
      {"--inlier-px",
       [&](auto v) {
         inlierPx = parseDouble("--inlier-px", v, 0.1, 100, "pixels from 0.1 to 100");
       }},
      {"--min-corners",
       [&](auto v) {
         limits.minCorners =
             static_cast<int>(parseDouble("--min-corners", v, 6, 100000, "a count from 6"));
       }},
      {"--max-rms-px",
       [&](auto v) {
         limits.maxRmsPx = parseDouble("--max-rms-px", v, 0.01, 100, "pixels from 0.01 to 100");
       }},
      {"--max-shift-m",
       [&](auto v) {
         limits.maxShiftM = parseDouble("--max-shift-m", v, 0.001, 100, "metres from 0.001 to 100");
       }},
      {"--max-turn-deg",
       [&](auto v) {
         limits.maxTurnDeg =
             parseDouble("--max-turn-deg", v, 0.01, 180, "degrees from 0.01 to 180");
       }},
      {"--max-seam-cm", [&](auto v) {
         limits.maxSeamCm = parseDouble("--max-seam-cm", v, 0.01, 1000, "centimetres from 0.01");
       }}};
}

double parseDouble(std::string_view option, std::string_view text, double min, double max,
                   std::string_view expected) {
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value) ||
      value < min || value > max) {
    throw UsageError(fmt::format("{}: expected {}, got '{}'", option, expected, text));
  }
  return value;
}

void parseOptions(std::span<const std::string_view> arguments, const Handlers& valued,
                  const Handlers& flags) {
  for (std::size_t i = 0; i < arguments.size(); ++i) {
    const std::string_view option = arguments[i];
    if (const auto flag = flags.find(option); flag != flags.end()) {
      flag->second("");
    } else if (const auto handler = valued.find(option); handler != valued.end()) {
      if (i + 1 >= arguments.size()) throw UsageError(fmt::format("{}: missing its value", option));
      handler->second(arguments[++i]);
    } else {
      throw UsageError(fmt::format("unknown option '{}' (see --help)", option));
    }
  }
}

Command parseArguments(std::span<const std::string_view> arguments) {
  if (arguments.empty()) {
    throw UsageError(
        "missing the subcommand: intrinsics, guide, extrinsics, import, mask or refine (see "
        "--help)");
  }
  const std::string_view subcommand = arguments.front();
  const auto rest = arguments.subspan(1);
  if (subcommand == "--help" || subcommand == "-h" || subcommand == "help") {
    return HelpRequest{usage()};
  }
  if (subcommand == "--version") return HelpRequest{versionText("surround-calibrate")};
  if (subcommand == "intrinsics") {
    if (asksForHelp(rest))
      return HelpRequest{fmt::format("{}\n{}", kIntrinsicsUsage, kUpdateRigUsage)};
    return parseIntrinsics(rest);
  }
  if (subcommand == "extrinsics") {
    if (asksForHelp(rest))
      return HelpRequest{fmt::format("{}\n{}", kExtrinsicsUsage, kUpdateRigUsage)};
    return parseExtrinsics(rest);
  }
  if (subcommand == "import") {
    if (asksForHelp(rest)) return HelpRequest{std::string(kImportUsage)};
    return parseImport(rest);
  }
  if (subcommand == "mask") {
    if (asksForHelp(rest)) return HelpRequest{std::string(kMaskUsage)};
    return parseMask(rest);
  }
  if (subcommand == "refine") {
    if (asksForHelp(rest)) return HelpRequest{std::string(kRefineUsage)};
    return parseRefine(rest);
  }
  if (subcommand == "guide") {
    if (asksForHelp(rest)) {
      return HelpRequest{fmt::format("{}\n{}\n{}", kGuideUsage, kMatGuideUsage, kUpdateRigUsage)};
    }
    if (std::find(rest.begin(), rest.end(), "--mat") != rest.end()) return parseMatGuide(rest);
    return parseGuide(rest);
  }
  throw UsageError(
      fmt::format("unknown subcommand '{}': expected intrinsics, guide, extrinsics, import, mask "
                  "or refine (see --help)",
                  subcommand));
}

std::string usage() {
  return fmt::format(
      "surround-calibrate: camera calibration for surroundd.\n\n{}\n{}\n{}\n{}\n{}\n{}\n{}\n{}\n"
      "exit status: 0 done, 1 calibration failed (too little in the images), 2 bad arguments or "
      "input files\n",
      kIntrinsicsUsage, kGuideUsage, kMatGuideUsage, kExtrinsicsUsage, kUpdateRigUsage,
      kImportUsage, kMaskUsage, kRefineUsage);
}

cv::Size imageSizeFrom(double width, double height, std::string_view where) {
  constexpr double kMaxSide = 65536;
  if (!(width >= 1 && width <= kMaxSide && height >= 1 && height <= kMaxSide)) {
    throw UsageError(fmt::format("{}: expected an image size of 1 to {} pixels a side, got {} x {}",
                                 where, kMaxSide, width, height));
  }
  return {static_cast<int>(width), static_cast<int>(height)};
}

}  // namespace surroundd::calibrate
