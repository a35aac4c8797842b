#include "tools/calibrate/recorded_camera.hpp"

#include <fmt/format.h>

#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {

std::filesystem::path recordingRigFile(const std::filesystem::path& given) {
  return std::filesystem::is_directory(given) ? given / "rig.yaml" : given;
}

std::unique_ptr<capture::FileSource> openRecordedCamera(const daemon::RigCamera& camera,
                                                        const std::filesystem::path& recording) {
  const std::string& name = camera.calibration.name;
  if (!camera.replayedFile()) {
    throw UsageError(
        fmt::format("{}: camera '{}' is live, not recorded: record a drive first "
                    "(a recording output), then give its folder",
                    recording.string(), name));
  }
  auto settings = *camera.replayedFile();
  settings.pacing = capture::Pacing::kAsFastAsPossible;
  settings.loop = false;
  std::unique_ptr<capture::FileSource> source;
  try {
    source = std::make_unique<capture::FileSource>(name, settings);
  } catch (const capture::CaptureError& error) {
    throw UsageError(error.what());
  }
  const cv::Size size = camera.calibration.intrinsics.imageSize;
  if (source->frameSize() != size) {
    throw UsageError(
        fmt::format("camera '{}': {} has {}x{} frames but the lens is calibrated "
                    "for {}x{}",
                    name, settings.path.string(), source->frameSize().width,
                    source->frameSize().height, size.width, size.height));
  }
  return source;
}

}  // namespace surroundd::calibrate
