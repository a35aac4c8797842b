#pragma once
// One still picture per camera in a folder (--images of import and of extrinsics --mat), named
// after the camera.

#include <filesystem>
#include <optional>
#include <string>

namespace surroundd::calibrate {

// The picture file (.png .jpg .jpeg .bmp .tif .tiff) whose name without its extension is the
// camera's, in any case; nullopt when there is none. UsageError when the folder is not one, or
// holds more than one picture for the camera.
std::optional<std::filesystem::path> findPicture(const std::filesystem::path& folder,
                                                 const std::string& camera);

}  // namespace surroundd::calibrate
