#include "common/atomic_file.hpp"

#include <fstream>
#include <stdexcept>
#include <system_error>

#include <fmt/format.h>

namespace surroundd {

void writeFileAtomically(const std::filesystem::path& file, std::string_view bytes,
                         const std::function<void(const std::filesystem::path&)>& check) {
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  const auto partial = std::filesystem::path(file.string() + ".part");
  const auto removePartial = [&] {
    std::error_code ignored;
    std::filesystem::remove(partial, ignored);
  };
  {
    std::ofstream stream(partial, std::ios::trunc | std::ios::binary);
    stream.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!stream.flush()) {
      stream.close();
      removePartial();
      throw std::runtime_error(fmt::format("{}: cannot write the file", file.string()));
    }
  }
  if (check) {
    try {
      check(partial);
    } catch (...) {
      removePartial();
      throw;
    }
  }
  std::error_code renamed;
  std::filesystem::rename(partial, file, renamed);
  if (renamed) {
    removePartial();
    throw std::runtime_error(
        fmt::format("{}: cannot replace the file ({})", file.string(), renamed.message()));
  }
}

}  // namespace surroundd
