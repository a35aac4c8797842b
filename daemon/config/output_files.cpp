#include "daemon/config/output_files.hpp"

#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <tuple>

#include <fmt/format.h>

#include "daemon/config/output_type.hpp"
#include "render/outputs/numbered_files.hpp"

namespace surroundd::daemon {
namespace {

// Paths compared as the files they are: symlinks in existing folders resolved.
std::filesystem::path resolved(const std::filesystem::path& path) {
  std::error_code ec;
  auto canonical = std::filesystem::weakly_canonical(std::filesystem::absolute(path), ec);
  return ec ? std::filesystem::absolute(path).lexically_normal() : canonical;
}

OutputPathUse pathUse(const OutputConfig& o) { return outputTypeOf(o).pathUse(o); }

// Whether `file`'s name is one of segmented output `o`'s: <stem>-<digits><ext> beside it.
bool isSegmentOf(const std::filesystem::path& file, const OutputConfig& o) {
  const auto own = resolved(o.path);
  if (file.parent_path() != own.parent_path() || file.extension() != own.extension()) return false;
  const std::string stem = file.stem().string();
  const std::string prefix = own.stem().string() + "-";
  if (!stem.starts_with(prefix) || stem.size() == prefix.size()) return false;
  return std::all_of(stem.begin() + static_cast<std::ptrdiff_t>(prefix.size()), stem.end(),
                     [](unsigned char c) { return std::isdigit(c) != 0; });
}

bool isInside(const std::filesystem::path& file, const std::filesystem::path& folder) {
  const auto relative = file.lexically_relative(folder);
  return !relative.empty() && *relative.begin() != "..";
}

// True where `path` holds something a run wrote: a file, or a folder with anything in it.
bool holdsData(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::symlink_status(path, ec);
  if (std::filesystem::is_directory(status)) {
    return !std::filesystem::is_empty(path, ec);
  }
  // A FIFO or a socket holds no data of ours (and a FIFO may be how a test stalls a writer).
  return std::filesystem::is_regular_file(status) || std::filesystem::is_symlink(status);
}

std::filesystem::path withPart(const std::filesystem::path& path) {
  return std::filesystem::path(path.string() + ".part");
}

}  // namespace

std::optional<std::string> outputFileClash(const OutputConfig& a, const OutputConfig& b) {
  if (a.path.empty() || b.path.empty()) return std::nullopt;
  const auto pa = resolved(a.path);
  const auto pb = resolved(b.path);
  if (pa == pb) {
    return a.path == b.path ? fmt::format("two outputs write '{}'", a.path.string())
                            : fmt::format("two outputs write '{}' (as '{}' and '{}')", pa.string(),
                                          a.path.string(), b.path.string());
  }
  for (const auto& [one, other, p1, p2] :
       {std::tuple{&a, &b, pa, pb}, std::tuple{&b, &a, pb, pa}}) {
    if (pathUse(*one) == OutputPathUse::kFolder && isInside(p2, p1)) {
      return fmt::format("'{}' is inside the recording folder '{}'", other->path.string(),
                         one->path.string());
    }
    if (pathUse(*one) == OutputPathUse::kSegments && isSegmentOf(p2, *one)) {
      return fmt::format("'{}' would be named like the segments of '{}'", other->path.string(),
                         one->path.string());
    }
  }
  return std::nullopt;
}

std::filesystem::path unusedOutputPath(const OutputConfig& output) {
  const OutputPathUse use = pathUse(output);
  const bool keepsData = use == OutputPathUse::kKept || use == OutputPathUse::kFolder;
  if (!keepsData || output.path.empty()) return output.path;
  // A kept file is written as <path>.part and renamed: a killed run's .part holds data too.
  const auto taken = [&](const std::filesystem::path& p) {
    return holdsData(p) || (use == OutputPathUse::kKept && holdsData(withPart(p)));
  };
  // After the highest number holding data, so that numbers go in the order the runs wrote them:
  // a video's retention removes the lowest, its own path first, which is then not taken again.
  std::int64_t n = -1;
  for (const auto& file : render::numberedFiles(output.path)) {
    if (holdsData(file.path)) n = std::max(n, file.number);
  }
  if (n < 0 && !taken(output.path)) return output.path;
  std::filesystem::path candidate;
  do {
    candidate = output.path;
    candidate.replace_filename(
        fmt::format("{}-{}{}", output.path.stem().string(), ++n, output.path.extension().string()));
  } while (taken(candidate));
  return candidate;
}

void createOutputFolder(const std::filesystem::path& folder, const std::filesystem::path& output) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) {
    throw std::runtime_error(fmt::format("output {}: cannot create the folder {}: {}",
                                         output.string(), folder.string(), ec.message()));
  }
}

}  // namespace surroundd::daemon
