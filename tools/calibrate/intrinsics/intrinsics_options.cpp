#include "tools/calibrate/intrinsics/intrinsics_options.hpp"

#include <charconv>

#include <fmt/format.h>

#include "processing/calibration/calibration_targets.hpp"
#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {

const std::string_view kIntrinsicsUsage =
    R"(usage: surround-calibrate intrinsics --images DIR (--board COLSxROWS | --charuco COLSxROWS)
                                  --model pinhole|fisheye --out FILE [options]

Intrinsics of one camera from a folder of pictures of a board (at many angles and all over the
image, its edges and corners too). Prints each picture's detection, a table of the views used
(corners, RMS, pose), every parameter with its standard deviation, the field of view and a
verdict; writes the camera's lens: block in the rig schema (daemon/config/rig_yaml.hpp) only when the
verdict is a pass. A failed solve writes nothing and exits 1, naming the views to drop.

Boards: any chessboard, square (7x7, 8x8) or not, and ChArUco boards. For intrinsics a board's
orientation does not matter (each view has its own pose), so the two ends may look alike, and
a board may be cut off at the image edge: a chessboard needs a 4x4 block of its corners in view
(the whole board when it is smaller), a ChArUco board two markers and 9 corners. A picture that
shows a larger chessboard grid than --board names means the size is wrong: it is refused early.
Pictures that are too blurred (--max-edge-width-px) or repeat an earlier view (the board where
it already was) are skipped with a note.

  --images DIR               folder of images (.png .jpg .jpeg .bmp .tif .tiff .pgm .ppm .pnm),
                             one camera, one resolution
  --board COLSxROWS          a chessboard's inner corners (where four squares meet), each 2 to
                             64: a board of 10x7 squares has 9x6
  --charuco COLSxROWS        a ChArUco board's squares (not corners), each 3 to 64
  --dictionary NAME          ChArUco: the markers' dictionary: 4x4_50 (default), 5x5_100,
                             6x6_250, apriltag_36h11, ... (an unknown name lists them all)
  --marker-ratio R           ChArUco: marker side / square side (default 0.7)
  --square MM                the square's side in millimetres: only scales the poses in the
                             table; intrinsics do not depend on it (default: poses in squares)
  --model MODEL              pinhole (radial-tangential, k1 k2 p1 p2 k3) or fisheye
                             (Kannala-Brandt, k1..k4)
  --out FILE                 the lens: block (YAML)
  --exclude NAME[,NAME..]    leave these image files out (repeatable)
  --residuals FILE           a PNG of every corner with its residual drawn --residual-scale
                             times longer, with a legend
  --residual-scale X         fixed magnification of the residual lines (default 50)
  --coverage FILE            a PNG of where the corners fell: covered cells green, empty ones
                             inside the lens red, outside the lens dark
  --field-of-view-deg D      fisheye: the lens's full field; default: to the edge of the image
                             circle the pictures show (at most 180 deg when the circle fills the
                             pictures, and never past where the distortion stops increasing)
  --update-rig FILE          also write the lens into this rig file (see "--update-rig" below)
  --camera NAME              with --update-rig: the camera to update
  --detect-timeout-s S       give up the board search in one picture after S seconds of its CPU
                             time (default 10; the machine's load does not change which count)
limits of the verdict (a solve outside any of them fails). By default the pixel limits scale
with the pictures: blur moves corners by a share of the edges' width, and a board seen large may
be blurred more before its corners move; each is the larger of its value and that share. Given,
a pixel limit is exactly what is given:
  --max-rms-px X             RMS over all corners (default 1, or 0.35 of the views' median edge
                             width)
  --max-view-rms-px X        a view above it is left out and named (default 2, or 0.7 of its
                             edge width)
  --max-edge-width-px X      pictures with wider (blurred) edges are skipped (default 4, or a
                             tenth of the board's squares in that picture)
  --max-focal-sd-percent P   the solve's focal length, one standard deviation (default 0.5 %;
                             the guide asks 0.1 %)
  --max-principal-sd-px X    the solve's principal point, one standard deviation (default 2 px;
                             the guide asks 0.3 px)
  --min-coverage F           share of the lens's image cells with corners, 0..1 (default 0.35)
  --min-views N              views needed (default 5)
)";

namespace {

cv::Size parseGrid(std::string_view option, std::string_view text, int minimum,
                   std::string_view what) {
  const auto fail = [&] {
    return UsageError(fmt::format("{}: expected COLSxROWS {}, each {} to 64 (e.g. 9x6), got '{}'",
                                  option, what, minimum, text));
  };
  const auto x = text.find('x');
  if (x == std::string_view::npos) throw fail();
  int cols = 0, rows = 0;
  const auto colsText = text.substr(0, x), rowsText = text.substr(x + 1);
  const auto a = std::from_chars(colsText.data(), colsText.data() + colsText.size(), cols);
  const auto b = std::from_chars(rowsText.data(), rowsText.data() + rowsText.size(), rows);
  if (a.ec != std::errc() || a.ptr != colsText.data() + colsText.size() || b.ec != std::errc() ||
      b.ptr != rowsText.data() + rowsText.size() || cols < minimum || rows < minimum || cols > 64 ||
      rows > 64) {
    throw fail();
  }
  return {cols, rows};
}

void splitNames(std::string_view list, std::vector<std::string>& names) {
  while (!list.empty()) {
    const auto comma = list.find(',');
    if (const auto name = list.substr(0, comma); !name.empty()) names.emplace_back(name);
    list = comma == std::string_view::npos ? std::string_view() : list.substr(comma + 1);
  }
}

}  // namespace

IntrinsicsOptions parseIntrinsics(std::span<const std::string_view> arguments) {
  return parseLensOptions(arguments, {}, {}, true);
}

IntrinsicsOptions parseLensOptions(std::span<const std::string_view> arguments, Handlers valued,
                                   const Handlers& flags, bool pictureFolder) {
  IntrinsicsOptions o;
  bool model = false, chessboard = false, charuco = false;
  std::optional<std::string> dictionary;
  std::optional<double> markerRatio;
  // The rig takes OCamCalib lenses, but this tool does not solve them: say where one comes from.
  const auto wrongModel = [](std::string_view v) {
    return UsageError(fmt::format("--model: expected 'pinhole' or 'fisheye', got '{}'{}", v,
                                  v == "ocam" ? " (calibrate an OCamCalib lens with OCamCalib and "
                                                "write its polynomials into the rig's lens block)"
                                              : ""));
  };
  auto& limits = o.limits;
  const auto limit = [](std::string_view option, double& field, double min, double max,
                        std::string_view expected) {
    return [=, &field](std::string_view v) { field = parseDouble(option, v, min, max, expected); };
  };
  // A pixel limit given is the limit itself: the share of the pictures no longer raises it.
  const auto exactLimit = [&](std::string_view option, double& field, double& share) {
    return [&field, &share, option](std::string_view v) {
      field = parseDouble(option, v, 0.01, 100, "pixels, 0.01 to 100");
      share = 0;
    };
  };
  Handlers lensOptions{
      {"--images", [&](auto v) { o.images = std::string(v); }},
      {"--board",
       [&](auto v) {
         o.board.size = parseGrid("--board", v, 2, "inner corners");
         chessboard = true;
       }},
      {"--charuco",
       [&](auto v) {
         o.board.size = parseGrid("--charuco", v, 3, "squares");
         o.board.kind = processing::BoardKind::kCharuco;
         charuco = true;
       }},
      {"--dictionary", [&](auto v) { dictionary = std::string(v); }},
      {"--marker-ratio",
       [&](auto v) {
         markerRatio = parseDouble("--marker-ratio", v, 0.1, 0.95, "a ratio from 0.1 to 0.95");
       }},
      {"--square",
       [&](auto v) { o.squareMm = parseDouble("--square", v, 0.1, 10000, "millimetres"); }},
      {"--model",
       [&](auto v) {
         // OpenCV solves these two; an OCamCalib lens comes from its own toolbox (import).
         const auto named = processing::lensModelNamed(v);
         if (!named || *named == processing::LensModel::kOcam) throw wrongModel(v);
         o.model = *named;
         model = true;
       }},
      {"--out", [&](auto v) { o.out = std::string(v); }},
      {"--exclude", [&](auto v) { splitNames(v, o.exclude); }},
      {"--residuals", [&](auto v) { o.residuals = std::string(v); }},
      {"--residual-scale", limit("--residual-scale", o.residualScale, 1, 10000, "1 to 10000")},
      {"--coverage", [&](auto v) { o.coverage = std::string(v); }},
      {"--field-of-view-deg",
       [&](auto v) {
         o.fieldOfViewDeg = parseDouble("--field-of-view-deg", v, 1, 360, "degrees from 1 to 360");
       }},
      {"--update-rig", [&](auto v) { o.updateRig = std::string(v); }},
      {"--camera", [&](auto v) { o.camera = std::string(v); }},
      {"--detect-timeout-s",
       limit("--detect-timeout-s", o.detectTimeoutS, 0.1, 3600, "seconds from 0.1 to 3600")},
      {"--max-rms-px", exactLimit("--max-rms-px", limits.maxRmsPx, limits.rmsPerEdgeWidth)},
      {"--max-view-rms-px",
       exactLimit("--max-view-rms-px", limits.maxViewRmsPx, limits.viewRmsPerEdgeWidth)},
      {"--max-edge-width-px",
       exactLimit("--max-edge-width-px", limits.maxEdgeWidthPx, limits.edgeWidthPerSquare)},
      {"--max-focal-sd-percent", limit("--max-focal-sd-percent", limits.maxFocalSdPercent, 0.001,
                                       100, "a percentage, 0.001 to 100")},
      {"--max-principal-sd-px",
       limit("--max-principal-sd-px", limits.maxPrincipalSdPx, 0.01, 1000, "pixels, 0.01 to 1000")},
      {"--min-coverage", limit("--min-coverage", limits.minCoverage, 0, 1, "a share, 0 to 1")},
      {"--min-views", [&](auto v) {
         limits.minViews = static_cast<int>(
             parseDouble("--min-views", v, processing::kMinimumBoardViews, 1000,
                         fmt::format("a count from {}", processing::kMinimumBoardViews)));
       }}};
  valued.merge(lensOptions);
  parseOptions(arguments, valued, flags);
  if (pictureFolder && o.images.empty()) {
    throw UsageError("--images: missing (the folder of board images)");
  }
  if (!pictureFolder && (!o.images.empty() || !o.exclude.empty() || o.residuals || o.coverage)) {
    throw UsageError(
        "--images, --exclude, --residuals and --coverage are for a folder of pictures "
        "(surround-calibrate intrinsics); the guide reads a camera (--device or --file)");
  }
  if (chessboard && charuco) throw UsageError("--board and --charuco: give one board");
  if (!chessboard && !charuco) {
    throw UsageError("--board: missing (a chessboard's inner corners, e.g. 9x6; or --charuco)");
  }
  if (!charuco && (dictionary || markerRatio)) {
    throw UsageError("--dictionary and --marker-ratio describe a --charuco board");
  }
  if (charuco) {
    const auto id = processing::arucoDictionaryByName(dictionary.value_or("4x4_50"));
    if (!id) {
      throw UsageError(fmt::format("--dictionary: unknown '{}' (known: {})", *dictionary,
                                   processing::arucoDictionaryNames()));
    }
    o.board.arucoDictionary = *id;
    o.board.markerToSquare = markerRatio.value_or(o.board.markerToSquare);
  }
  if (!model) throw UsageError("--model: missing (pinhole or fisheye)");
  if (o.out.empty()) throw UsageError("--out: missing (the file to write the lens: block to)");
  if (o.fieldOfViewDeg && o.model != processing::LensModel::kFisheye) {
    throw UsageError("--field-of-view-deg: only a fisheye lens takes it");
  }
  if (o.updateRig.has_value() != !o.camera.empty()) {
    throw UsageError("--update-rig and --camera go together (the rig file and its camera)");
  }
  return o;
}

}  // namespace surroundd::calibrate
