#pragma once
// What surround-calibrate writes: the camera's lens: or mount: block in the rig schema
// (daemon/rig_yaml.hpp), ready to paste under the camera, and optionally the same values written
// into a rig file. Every file is written beside and renamed, so a reader never sees half of one.

#include <filesystem>
#include <string>
#include <string_view>

#include "processing/rig.hpp"

namespace surroundd::calibrate {

// `comment`: lines for the file's head (how the values were obtained).
void writeLensBlock(const std::filesystem::path& file, const processing::Intrinsics& lens,
                    std::string_view comment);
void writeMountBlock(const std::filesystem::path& file, const processing::Pose& pose,
                     std::string_view comment);

// Replaces one camera's lens or pose in a rig file (read and rewritten with daemon's rig reader
// and writer, so it stays valid). Throws UsageError when the rig has no camera of that name.
void updateRigLens(const std::filesystem::path& rig, const std::string& camera,
                   const processing::Intrinsics& lens, std::string_view comment);
void updateRigMount(const std::filesystem::path& rig, const std::string& camera,
                    const processing::Pose& pose, std::string_view comment);

// The camera of that name in a rig file; UsageError listing the names when there is none.
processing::CameraCalibration rigCamera(const std::filesystem::path& rig,
                                        const std::string& camera);

}  // namespace surroundd::calibrate
