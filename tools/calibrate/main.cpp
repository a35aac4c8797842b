// surround-calibrate: camera intrinsics from checkerboard images, extrinsics from ground markers,
// other tools' calibrations imported into a rig file, the body masks drawn for checking, and the
// mounts refined from the road (see --help).

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string_view>
#include <vector>

#include "daemon/config/yaml_reader.hpp"
#include "daemon/outputs/built_in_outputs.hpp"
#include "processing/calibration/calibration_error.hpp"
#include "tools/calibrate/calibrate_options.hpp"
#include "tools/calibrate/extrinsics/extrinsics_command.hpp"
#include "tools/calibrate/guide/guide_command.hpp"
#include "tools/calibrate/guide/mat_guide_command.hpp"
#include "tools/calibrate/import/import_command.hpp"
#include "tools/calibrate/intrinsics/intrinsics_command.hpp"
#include "tools/calibrate/mask/mask_command.hpp"
#include "tools/calibrate/refine/refine_command.hpp"

namespace {

int run(const std::vector<std::string_view>& arguments) {
  using namespace surroundd::calibrate;
  std::string_view subcommand = arguments.empty() ? "" : arguments.front();
  const std::string prefix = subcommand == "intrinsics" || subcommand == "extrinsics" ||
                                     subcommand == "import" || subcommand == "mask" ||
                                     subcommand == "refine" || subcommand == "guide"
                                 ? "surround-calibrate " + std::string(subcommand) + ": "
                                 : std::string("surround-calibrate: ");
  try {
    const Command command = parseArguments(arguments);
    if (const auto* help = std::get_if<HelpRequest>(&command)) {
      std::cout << help->text;
    } else if (const auto* intrinsics = std::get_if<IntrinsicsOptions>(&command)) {
      runIntrinsics(*intrinsics, std::cout);
    } else if (const auto* guide = std::get_if<GuideOptions>(&command)) {
      runGuide(*guide, std::cout);
    } else if (const auto* matGuide = std::get_if<MatGuideOptions>(&command)) {
      runMatGuide(*matGuide, std::cout);
    } else if (const auto* import = std::get_if<ImportOptions>(&command)) {
      runImport(*import, std::cout);
    } else if (const auto* mask = std::get_if<MaskOptions>(&command)) {
      runMask(*mask, std::cout);
    } else if (const auto* refine = std::get_if<RefineOptions>(&command)) {
      runRefine(*refine, std::cout);
    } else {
      runExtrinsics(std::get<ExtrinsicsOptions>(command), std::cout);
    }
    return 0;
  } catch (const UsageError& error) {
    std::cerr << prefix << error.what() << "\n";
    return 2;
  } catch (const surroundd::daemon::ConfigError& error) {
    for (const auto& message : error.messages()) std::cerr << prefix << message << "\n";
    return 2;
  } catch (const surroundd::processing::CalibrationError& error) {
    std::cerr << prefix << "calibration failed: " << error.what() << "\n";
    return 1;
  } catch (const std::exception& error) {
    std::cerr << prefix << "failed: " << error.what() << "\n";
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  // `mask` and `refine` read the daemon's config, its outputs too.
  surroundd::daemon::registerBuiltInOutputTypes();
  const int status = run({argv + 1, argv + argc});
  // The intrinsics' board search may have left a detection thread running past its time bound
  // (processing/calibration/picture_search.hpp): static destructors must not run under it, so the
  // process ends here, with its output flushed, without them. Every file was written whole before
  // this (calibration_output.cpp writes a .part and renames it), so none is left half-written.
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);  // whatever a library wrote through C's stdio
  std::_Exit(status);
}
