#pragma once
// Still pictures as PNG, through FFmpeg's encoder (the one that writes the videos' library):
// encoded in memory, or written whole or not at all (to "<path>.part", then renamed). Throws
// std::runtime_error naming the file or what failed.

#include <cstdint>
#include <filesystem>
#include <vector>

#include <opencv2/core.hpp>

namespace surroundd::render {

// An 8-bit BGR picture as the bytes of a PNG file.
std::vector<std::uint8_t> encodePng(const cv::Mat& bgr);
// `image` (8-bit BGR) as the PNG file `path`.
void writeImageFile(const std::filesystem::path& path, const cv::Mat& image);

}  // namespace surroundd::render
