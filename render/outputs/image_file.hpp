#pragma once
// Still images written whole or not at all: encoded in memory, written to "<path>.part", renamed.
// The format follows the extension (.png, .jpg/.jpeg). Throws std::runtime_error naming the file.

#include <filesystem>

#include <opencv2/core.hpp>

namespace surroundd::render {

void writeImageFile(const std::filesystem::path& path, const cv::Mat& image);

}  // namespace surroundd::render
