// `surround-calibrate import` on any file of each format it reads: an OpenCV FileStorage
// calibration (YAML, JSON or XML), OCamCalib's calib_results.txt, PJLab's calibration.yaml. The
// first byte picks the format, the rest is the file. The import gives cameras the daemon can use
// (rig_invariants.hpp) and a rig file that reads back, or UsageError (or ConfigError from the
// rig's writer); anything else (a crash, a hang, unbounded memory, NaN written) is a finding.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "tests/fuzz/fuzz_support.hpp"
#include "tests/fuzz/rig_invariants.hpp"
#include "tools/calibrate/calibrate_options.hpp"
#include "tools/calibrate/import/import_command.hpp"

namespace {

struct Format {
  const char* fileName;
  bool pjlab;
};
constexpr std::array<Format, 5> kFormats{{{"front.yml", false},
                                          {"front.json", false},
                                          {"front.xml", false},
                                          {"calib_results.txt", false},
                                          {"calibration.yaml", true}}};

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  surroundd::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const Format& format = kFormats[data[0] % kFormats.size()];
  const auto folder = surroundd::fuzz::scratchFolder();
  const auto file = folder / format.fileName;
  surroundd::fuzz::writeFile(file, surroundd::fuzz::asText(data + 1, size - 1));
  surroundd::calibrate::ImportOptions options;
  if (format.pjlab) {
    options.pjlabYaml = file;
  } else {
    options.cameraFiles["front"] = {file};
    options.imageSize = cv::Size(640, 480);  // where the file has none
  }
  // A homography's canvas, for files that give one.
  options.canvasScale = 0.01;
  options.out = folder / "rig.yaml";
  try {
    surroundd::calibrate::runImport(options, surroundd::fuzz::discardedLog());
    const auto rig = surroundd::daemon::loadRigFile(options.out);
    surroundd::fuzz::checkAcceptedCameras(rig);
  } catch (const surroundd::calibrate::UsageError&) {
    // the documented answer to a file that does not import
  } catch (const surroundd::daemon::ConfigError&) {
    // a rig the writer refuses (a number that is not finite), nothing written
  }
  return 0;
}
