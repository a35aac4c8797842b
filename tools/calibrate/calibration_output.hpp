#pragma once
// What surround-calibrate writes: the camera's lens: or mount: block in the rig schema
// (daemon/rig_yaml.hpp), ready to paste under the camera, and optionally the same values written
// into a rig file; the mask pictures. Every file is written beside and renamed, so a reader never
// sees half of one.

#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include <opencv2/core.hpp>

#include "processing/rig.hpp"

namespace surroundd::calibrate {

// `comment`: lines for the file's head (how the values were obtained).
void writeLensBlock(const std::filesystem::path& file, const processing::Intrinsics& lens,
                    std::string_view comment);
void writeMountBlock(const std::filesystem::path& file, const processing::Pose& pose,
                     std::string_view comment);

// Several cameras' mount: blocks, each under its name in a cameras: list (the rig's own layout).
void writeMountBlocks(const std::filesystem::path& file,
                      std::span<const std::pair<std::string, processing::Pose>> mounts,
                      std::string_view comment);

// A PNG of `picture` (8-bit, 1 or 3 channels).
void writePng(const std::filesystem::path& file, const cv::Mat& picture);

// Replaces one camera's lens: or mount: block in a rig file, editing the YAML document: every
// other key (sources with their sequence_fps, health, other cameras, ...) stays, and so does the
// file's leading comment block, verbatim; comments inside the document are lost (yaml-cpp keeps
// none), and `comment` goes on one line beside the new block. The result must read back through
// daemon::loadRigFile to the new calibration, or nothing is written (std::runtime_error). Throws
// UsageError when the rig has no camera of that name.
void updateRigLens(const std::filesystem::path& rig, const std::string& camera,
                   const processing::Intrinsics& lens, std::string_view comment);
void updateRigMount(const std::filesystem::path& rig, const std::string& camera,
                    const processing::Pose& pose, std::string_view comment);
// Several cameras' mounts in one edit of the rig file: it takes all of them or, when one cannot
// be written, none (the file is replaced once, by rename).
void updateRigMounts(const std::filesystem::path& rig,
                     std::span<const std::pair<std::string, processing::Pose>> mounts,
                     std::string_view comment);

// The camera of that name in a rig file; UsageError listing the names when there is none.
processing::CameraCalibration rigCamera(const std::filesystem::path& rig,
                                        const std::string& camera);

}  // namespace surroundd::calibrate
