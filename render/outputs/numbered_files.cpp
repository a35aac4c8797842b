#include "render/outputs/numbered_files.hpp"

#include <algorithm>
#include <charconv>
#include <string_view>
#include <system_error>

#include <fmt/format.h>

namespace surroundd::render {

std::vector<NumberedFile> numberedFiles(const std::filesystem::path& path) {
  const auto folder = path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
  const std::string stem = path.stem().string();
  const std::string extension = path.extension().string();
  std::vector<NumberedFile> files;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    std::string name = entry.path().filename().string();
    if (name.ends_with(".part")) name.resize(name.size() - 5);
    if (!name.starts_with(stem) || !name.ends_with(extension) ||
        name.size() < stem.size() + extension.size()) {
      continue;
    }
    const std::string_view middle(name.data() + stem.size(),
                                  name.size() - stem.size() - extension.size());
    std::int64_t number = 0;
    if (!middle.empty()) {
      const std::string_view digits = middle.substr(1);
      if (middle[0] != '-' || digits.empty() ||
          digits.find_first_not_of("0123456789") != std::string_view::npos) {
        continue;
      }
      std::uint64_t value = 0;
      const auto [end, failed] =
          std::from_chars(digits.data(), digits.data() + digits.size(), value);
      const bool past = failed == std::errc::result_out_of_range ||
                        value > static_cast<std::uint64_t>(kMaxFileNumber);
      number = past ? kMaxFileNumber : static_cast<std::int64_t>(value);
    }
    std::error_code sizeError;
    const auto bytes = entry.is_regular_file(sizeError) ? entry.file_size(sizeError) : 0;
    files.push_back({number, entry.path(), sizeError ? 0 : bytes});
  }
  std::ranges::sort(files, [](const NumberedFile& a, const NumberedFile& b) {
    return a.number != b.number ? a.number < b.number : a.path < b.path;
  });
  return files;
}

std::string describe(const Retention& retention) {
  std::string text;
  if (retention.keepLast > 0) text = fmt::format("the newest {}", retention.keepLast);
  if (retention.maxBytes > 0) {
    text += fmt::format("{}at most {:.0f} MB together", text.empty() ? "" : ", ",
                        static_cast<double>(retention.maxBytes) / 1e6);
  }
  return text.empty() ? "every file" : text;
}

std::vector<std::filesystem::path> retainNewest(const Retention& retention,
                                                const std::filesystem::path& writing) {
  std::vector<NumberedFile> kept = numberedFiles(retention.family);
  const std::string name = writing.filename().string();
  std::erase_if(kept, [&](const NumberedFile& f) {
    const std::string other = f.path.filename().string();
    return other == name || other == name + ".part";
  });
  // The file being written counts as one of those kept.
  const auto tooMany = [&] {
    std::uint64_t bytes = 0;
    for (const auto& file : kept) bytes += file.bytes;
    return (retention.keepLast > 0 &&
            kept.size() + 1 > static_cast<std::size_t>(retention.keepLast)) ||
           (retention.maxBytes > 0 && bytes > retention.maxBytes);
  };
  std::vector<std::filesystem::path> removed;
  while (!kept.empty() && tooMany()) {
    std::error_code error;
    if (std::filesystem::remove(kept.front().path, error)) removed.push_back(kept.front().path);
    kept.erase(kept.begin());
  }
  return removed;
}

}  // namespace surroundd::render
