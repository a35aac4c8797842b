#pragma once
// One still picture per camera in a folder (--images of import and of extrinsics --mat), named
// after the camera.

#include <filesystem>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "processing/rig.hpp"

namespace surroundd::calibrate {

// The picture file (.png .jpg .jpeg .bmp .tif .tiff) whose name without its extension is the
// camera's, in any case; nullopt when there is none. UsageError when the folder is not one, or
// holds more than one picture for the camera.
std::optional<std::filesystem::path> findPicture(const std::filesystem::path& folder,
                                                 const std::string& camera);

// findPicture's file; UsageError naming the camera and the names looked for when there is none.
std::filesystem::path requirePicture(const std::filesystem::path& folder,
                                     const std::string& camera);

// UsageError when a picture of `file` (`size`) is not the size of the camera's lens in `rig`.
void checkPictureSize(const std::filesystem::path& file, cv::Size size,
                      const processing::CameraCalibration& camera,
                      const std::filesystem::path& rig);

}  // namespace surroundd::calibrate
