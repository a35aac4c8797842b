#pragma once
// A camera of a recorded drive, read as fast as it decodes from its first frame to its last (no
// loop): what surround-calibrate mask --from and refine read.

#include <filesystem>
#include <memory>

#include "capture/file_source.hpp"
#include "daemon/config/rig_yaml.hpp"

namespace surroundd::calibrate {

// The rig file of a recording given as its folder (with rig.yaml) or as the file itself.
std::filesystem::path recordingRigFile(const std::filesystem::path& given);

// Opens `camera`'s recorded source. Throws UsageError naming `recording` and the camera when it is
// live, cannot be opened, or has frames of another size than its lens.
std::unique_ptr<capture::FileSource> openRecordedCamera(const daemon::RigCamera& camera,
                                                        const std::filesystem::path& recording);

}  // namespace surroundd::calibrate
