#pragma once
// What surround-calibrate writes: the camera's lens: or mount: block in the rig schema
// (daemon/config/rig_yaml.hpp), ready to paste under the camera, and optionally the same values
// written into a rig file; the mask pictures. Every file is written beside and renamed, so a reader
// never sees half of one.

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

// Replaces one camera's lens: or mount: value in a rig file, in its text (rig_text_edit.hpp):
// every other byte stays as it was (comments, order, style, other cameras, keys of the user's
// own), and `comment` goes on one line beside the new value. The result must read back through
// daemon::loadRigFile to the new calibration, or nothing is written (std::runtime_error). Throws
// UsageError when the rig has no camera of that name, and when a lens's pictures are of another
// size than the camera's (checkRigPictureSize).
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
// UsageError naming both sizes when camera `camera` of `rig` takes pictures of another size than
// `pictures`: a lens fitted to them does not fit it (one of 640x480 was once written over a
// 1920x1280 camera without a word).
void checkRigPictureSize(const std::filesystem::path& rig, const std::string& camera,
                         cv::Size pictures);

}  // namespace surroundd::calibrate
