#include "render/outputs/image_file.hpp"

#include <fstream>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

namespace surroundd::render {

void writeImageFile(const std::filesystem::path& path, const cv::Mat& image) {
  std::vector<std::uint8_t> bytes;
  const std::string extension = path.extension().string();
  if (!cv::imencode(extension, image, bytes)) {
    throw std::runtime_error(fmt::format("cannot encode '{}' as {}", path.string(), extension));
  }
  std::filesystem::path part = path;
  part += ".part";
  {
    std::ofstream file(part, std::ios::binary | std::ios::trunc);
    file.write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
    file.close();
    if (!file) {
      std::error_code ignored;
      std::filesystem::remove(part, ignored);
      throw std::runtime_error(fmt::format("cannot write '{}'", part.string()));
    }
  }
  std::filesystem::rename(part, path);
}

}  // namespace surroundd::render
