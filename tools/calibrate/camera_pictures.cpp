#include "tools/calibrate/camera_pictures.hpp"

#include <algorithm>
#include <cctype>
#include <vector>

#include <fmt/format.h>

#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {
namespace {

std::string lower(std::string text) {
  std::ranges::transform(text, text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

}  // namespace

std::optional<std::filesystem::path> findPicture(const std::filesystem::path& folder,
                                                 const std::string& camera) {
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) {
    throw UsageError(fmt::format("--images: {} is not a folder", folder.string()));
  }
  std::vector<std::filesystem::path> matches;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    const auto extension = lower(entry.path().extension().string());
    const bool picture = extension == ".png" || extension == ".jpg" || extension == ".jpeg" ||
                         extension == ".bmp" || extension == ".tif" || extension == ".tiff";
    if (picture && lower(entry.path().stem().string()) == lower(camera)) {
      matches.push_back(entry.path());
    }
  }
  if (matches.size() > 1) {
    throw UsageError(fmt::format("--images: {} has more than one picture for camera '{}'",
                                 folder.string(), camera));
  }
  if (matches.empty()) return std::nullopt;
  return matches.front();
}

std::filesystem::path requirePicture(const std::filesystem::path& folder,
                                     const std::string& camera) {
  auto file = findPicture(folder, camera);
  if (!file) {
    throw UsageError(fmt::format(
        "--images: {} holds no picture of camera '{}' (looked for {}.png, .jpg, .jpeg, .bmp, "
        ".tif, .tiff)",
        folder.string(), camera, camera));
  }
  return *file;
}

void checkPictureSize(const std::filesystem::path& file, cv::Size size,
                      const processing::CameraCalibration& camera,
                      const std::filesystem::path& rig) {
  const cv::Size lens = camera.intrinsics.imageSize;
  if (size != lens) {
    throw UsageError(fmt::format(
        "--images: {} is {}x{}, but camera '{}' in {} has a {}x{} lens; calibrate the intrinsics "
        "at this resolution first",
        file.string(), size.width, size.height, camera.name, rig.string(), lens.width,
        lens.height));
  }
}

}  // namespace surroundd::calibrate
