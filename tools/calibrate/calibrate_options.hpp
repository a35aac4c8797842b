#pragma once
// Command line of surround-calibrate: one subcommand per calibration, each validated completely
// before anything is read; a problem throws UsageError naming the option (main prints it and
// exits 2).

#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/mat_calibration.hpp"
#include "processing/lens/camera_model.hpp"
#include "render/outputs/credentials.hpp"
#include "tools/calibrate/guide/guide_options.hpp"
#include "tools/calibrate/guide/mat_guide_options.hpp"
#include "tools/calibrate/import/import_options.hpp"
#include "tools/calibrate/intrinsics/intrinsics_options.hpp"

namespace surroundd::calibrate {

// Bad arguments or input files: what the user passed has to change (exit status 2).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ExtrinsicsOptions {
  std::filesystem::path rig;  // lens and nominal mount of the camera
  std::string camera;
  std::filesystem::path image;
  std::optional<std::filesystem::path> markers;    // ground marker layout
  std::optional<std::filesystem::path> points;     // explicit vehicle point <-> pixel pairs
  std::filesystem::path out;                       // the mount: block
  std::optional<std::filesystem::path> residuals;  // PNG
  double inlierPx = 3.0;
  bool updateRig = false;  // write the new mount into the rig file (every camera's, with --mat)
  // A calibration mat instead: every camera of the mat from its picture in `images`.
  std::optional<std::filesystem::path> mat;     // the mat's layout (YAML)
  std::optional<std::filesystem::path> images;  // folder with one picture per camera, NAME.png
  processing::MatLimits limits;
};

struct MaskOptions {
  std::filesystem::path config;  // the surroundd config (its rig, vehicle: and body_mask:s)
  // Or a recording of a drive (its rig file, or the folder that holds rig.yaml): the body found in
  // its pictures.
  std::filesystem::path from;
  std::filesystem::path out;  // folder for the pictures
  std::string camera;         // empty: every camera
  double everyS = 0.5;        // --every: seconds of the drive between the pictures looked at
};

struct RefineOptions {
  std::filesystem::path config;  // a surroundd config: its rig file, vehicle and body masks
  std::filesystem::path rig;     // or a rig file, or a recording's folder (with rig.yaml)
  // One still picture per camera, named after it; none: the cameras' recorded sources.
  std::optional<std::filesystem::path> images;
  double everyS = 0.5;        // --every: seconds of a recording between the sets looked at
  std::filesystem::path out;  // folder for mounts.yaml and the pictures
  bool updateRig = false;     // write the refined mounts into the rig file
};

struct HelpRequest {
  std::string text;
};

using Command = std::variant<IntrinsicsOptions, GuideOptions, MatGuideOptions, ExtrinsicsOptions,
                             ImportOptions, MaskOptions, RefineOptions, HelpRequest>;

// An image size read from a calibration file: each side 1 to 65536 pixels, checked before the
// cast (1e300 pixels fits no int); UsageError naming `where` otherwise.
cv::Size imageSizeFrom(double width, double height, std::string_view where);

// `arguments` excludes the program name. Throws UsageError.
Command parseArguments(std::span<const std::string_view> arguments);
std::string usage();

// Shared by the subcommands' parsers. Options that take a value: the handler gets it; flags: the
// handler gets "". Unknown options and a missing value throw UsageError.
using Handlers = std::map<std::string_view, std::function<void(std::string_view)>>;
void parseOptions(std::span<const std::string_view> arguments, const Handlers& valued,
                  const Handlers& flags);
// The lens options of surround-calibrate intrinsics (board, model, --out, limits, --update-rig)
// and `valued`/`flags` besides; `pictureFolder`: --images is required, otherwise refused.
IntrinsicsOptions parseLensOptions(std::span<const std::string_view> arguments, Handlers valued,
                                   const Handlers& flags, bool pictureFolder);
// The mat calibration's limits (--min-corners, --max-rms-px, --max-shift-m, --max-turn-deg,
// --max-seam-cm) and --inlier-px, of extrinsics --mat and guide --mat.
Handlers matLimitHandlers(processing::MatLimits& limits, double& inlierPx);
// A guide's camera request and page: --size WxH (sets `sizeGiven`), --fps, --listen ADDR:PORT,
// --password-file FILE; of guide and guide --mat. Defined in guide_options.cpp.
Handlers cameraAndPageHandlers(cv::Size& size, bool& sizeGiven, double& fps, std::string& address,
                               int& port, std::optional<std::filesystem::path>& passwordFile);
// Who may see a guide's page: the --password-file's user and password; none on 127.x.x.x without
// one; UsageError for a page beyond this machine without one, or a file that cannot be used.
std::optional<render::Credentials> pageCredentials(
    const std::string& address, const std::optional<std::filesystem::path>& passwordFile);
// A number in [min, max]; UsageError naming the option and `expected` otherwise.
double parseDouble(std::string_view option, std::string_view text, double min, double max,
                   std::string_view expected);

}  // namespace surroundd::calibrate
