#pragma once
// Cameras' lens: or mount: values replaced in a rig file, in its text (rig_text_edit.hpp): every
// other byte stays as it was (comments, order, style, other cameras, keys of the user's own), and
// `comment` goes on one line beside each new value. All the edits go into one file written beside
// the rig and renamed (common/atomic_file.hpp): the rig takes all of them or none, and only once
// it reads back through loadRigFile to the new calibration.
//
// Errors: std::invalid_argument naming the rig and what was wrong (no camera of that name, a value
// that cannot be edited in place); std::runtime_error when it cannot be written or would not read
// back (the rig is left as it was); ConfigError for a rig that does not load.

#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include "processing/lens/intrinsics.hpp"
#include "processing/rig.hpp"

namespace surroundd::daemon {

void updateRigLens(const std::filesystem::path& rig, const std::string& camera,
                   const processing::Intrinsics& lens, std::string_view comment);
// Several cameras' mounts (camera name, pose) in one edit.
void updateRigMounts(const std::filesystem::path& rig,
                     std::span<const std::pair<std::string, processing::Pose>> mounts,
                     std::string_view comment);

}  // namespace surroundd::daemon
