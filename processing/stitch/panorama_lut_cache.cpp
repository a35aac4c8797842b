#include "processing/stitch/panorama_lut_cache.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <type_traits>

#include <fmt/format.h>
#include <zlib.h>

#include "common/camera_limit.hpp"
#include "common/regular_file.hpp"

namespace surroundd::processing {
namespace {

constexpr char kMagic[8] = {'S', 'R', 'N', 'D', 'L', 'U', 'T', '\n'};
// Bump when the layout of the file or the way the LUT is built changes.
constexpr std::uint32_t kFormatVersion = 1;
// Above any LUT a panorama the config allows makes (16384 x 8192 pixels of 8-byte taps: 1 GiB,
// plus the blend taps): a larger file is no LUT of ours.
constexpr std::size_t kMaxFileBytes = std::size_t{3} << 30;

// The most bytes the LUT of `key` for a panorama of `panorama` pixels can take: the header, the
// key, the sizes of the panorama and every camera, a tap per pixel, at most two blend taps per
// pixel (there is one where two cameras meet), a blend row start per row, the checksum.
std::size_t maxFileBytesFor(const std::string& key, cv::Size panorama) {
  const auto pixels = static_cast<std::size_t>(std::max(panorama.width, 1)) *
                      static_cast<std::size_t>(std::max(panorama.height, 1));
  const std::size_t bytes =
      sizeof(kMagic) + sizeof(std::uint32_t) + 5 * sizeof(std::uint64_t) + key.size() +
      (1 + kMaxCameras) * 2 * sizeof(std::int32_t) + pixels * sizeof(LutTap) +
      2 * pixels * sizeof(BlendTap) +
      (static_cast<std::size_t>(std::max(panorama.height, 1)) + 1) * sizeof(std::uint32_t) +
      sizeof(std::uint32_t);
  return std::min(bytes, kMaxFileBytes);
}

std::uint32_t crc(const void* data, std::size_t bytes) {
  return static_cast<std::uint32_t>(
      crc32_z(crc32_z(0, nullptr, 0), static_cast<const Bytef*>(data), bytes));
}

class Writer {
 public:
  template <typename T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  template <typename T>
  void array(const std::vector<T>& values) {
    value(static_cast<std::uint64_t>(values.size()));
    bytes_.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  }
  void text(const std::string& s) {
    value(static_cast<std::uint64_t>(s.size()));
    bytes_ += s;
  }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

// Reads what Writer wrote; every read checks the remaining length, so a damaged count cannot make
// it read past the end.
class Reader {
 public:
  explicit Reader(std::string_view bytes) : bytes_(bytes) {}
  template <typename T>
  bool value(T& v) {
    if (bytes_.size() < sizeof(T)) return false;
    std::memcpy(&v, bytes_.data(), sizeof(T));
    bytes_.remove_prefix(sizeof(T));
    return true;
  }
  template <typename T>
  bool array(std::vector<T>& values) {
    std::uint64_t count = 0;
    if (!value(count) || count > bytes_.size() / sizeof(T)) return false;
    values.resize(count);
    // An empty vector's data() may be null, which memcpy must not get even for 0 bytes (UBSan
    // stopped the fuzz seed writer on a LUT without blend taps).
    if (count > 0) std::memcpy(values.data(), bytes_.data(), count * sizeof(T));
    bytes_.remove_prefix(count * sizeof(T));
    return true;
  }
  bool text(std::string& s) {
    std::uint64_t count = 0;
    if (!value(count) || count > bytes_.size()) return false;
    s.assign(bytes_.substr(0, count));
    bytes_.remove_prefix(count);
    return true;
  }
  bool atEnd() const { return bytes_.empty(); }

 private:
  std::string_view bytes_;
};

// The LUT's own invariants, so that a file that passes the checksum but was written by a faulty
// build cannot make the stitcher read outside a camera image.
bool consistent(const PanoramaLut& lut) {
  if (lut.size.width < 1 || lut.size.height < 1) return false;
  // In size_t: a damaged size's int area() overflows (found by the fuzz target).
  const auto pixels =
      static_cast<std::size_t>(lut.size.width) * static_cast<std::size_t>(lut.size.height);
  if (lut.taps.size() != pixels ||
      lut.blendRowBegin.size() != static_cast<std::size_t>(lut.size.height) + 1 ||
      lut.blendRowBegin.back() != lut.blendTaps.size()) {
    return false;
  }
  const auto tapInside = [&](const LutTap& tap) {
    if (tap.camera == PanoramaLut::kUnseen) return tap.offset == 0;
    if (tap.camera >= lut.cameraSizes.size() || tap.fx > LutTap::kFractionOne ||
        tap.fy > LutTap::kFractionOne) {
      return false;
    }
    const cv::Size size = lut.cameraSizes[tap.camera];
    return size.width >= 2 && size.height >= 2 &&
           tap.offset % size.width < static_cast<std::uint32_t>(size.width - 1) &&
           tap.offset / size.width < static_cast<std::uint32_t>(size.height - 1);
  };
  for (const auto& tap : lut.taps) {
    if (!tapInside(tap)) return false;
  }
  // Sorted and ending at the blend taps' count, so no row reaches past them: checked for every row
  // before any row is read (a later row going back down let an earlier one read past the end:
  // found by the fuzz target).
  if (!std::ranges::is_sorted(lut.blendRowBegin)) return false;
  for (std::size_t v = 0; v + 1 < lut.blendRowBegin.size(); ++v) {
    for (auto b = lut.blendRowBegin[v]; b < lut.blendRowBegin[v + 1]; ++b) {
      const BlendTap& blend = lut.blendTaps[b];
      if (blend.pixel / lut.size.width != v || blend.tap.camera == PanoramaLut::kUnseen ||
          !tapInside(blend.tap)) {
        return false;
      }
    }
  }
  return true;
}

}  // namespace

std::string panoramaLutKey(const Rig& rig, const PanoramaSettings& settings) {
  // Hexadecimal floats: exact, so any change of any input changes the key.
  std::string key = fmt::format("surroundd panorama LUT, format {}\n", kFormatVersion);
  for (const auto& camera : rig.cameras) {
    key += fmt::format("camera {}\n", lensKey(camera.intrinsics));
    const auto& r = camera.pose.rotation;
    const auto& t = camera.pose.position;
    key += fmt::format("  pose {:a} {:a} {:a} {:a} {:a} {:a} {:a} {:a} {:a} at {:a} {:a} {:a}\n",
                       r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1),
                       r(2, 2), t[0], t[1], t[2]);
    if (!camera.bodyMask.empty()) {
      const cv::Mat mask =
          camera.bodyMask.isContinuous() ? camera.bodyMask : camera.bodyMask.clone();
      key += fmt::format("  body mask {}x{} crc {:08x}\n", mask.cols, mask.rows,
                         crc(mask.data, mask.total() * mask.elemSize()));
    }
  }
  const auto& g = settings.geometry;
  const auto& b = settings.bowl;
  key += fmt::format(
      "panorama {}x{} elevation {:a} {:a} centre {:a} {:a} {:a} projection {} feather {:a}\n"
      "bowl {:a} {:a} {:a}\n",
      g.size.width, g.size.height, g.elevationTopRad, g.elevationBottomRad, g.centre[0],
      g.centre[1], g.centre[2],
      settings.projection == PanoramaProjection::kSphere ? "sphere" : "bowl", settings.featherRad,
      b.floorRadiusM, b.rimRadiusM, b.rimHeightM);
  return key;
}

std::filesystem::path PanoramaLutCache::fileFor(const std::string& key) const {
  return folder_ / fmt::format("panorama-{:08x}.lut", crc(key.data(), key.size()));
}

PanoramaLutCache::Lookup PanoramaLutCache::load(const std::string& key, cv::Size panorama) const {
  return read(fileFor(key), key, maxFileBytesFor(key, panorama));
}

PanoramaLutCache::Lookup PanoramaLutCache::loadFile(const std::filesystem::path& file) {
  return read(file, std::nullopt, kMaxFileBytes);
}

PanoramaLutCache::Lookup PanoramaLutCache::read(const std::filesystem::path& path,
                                                std::optional<std::string_view> key,
                                                std::size_t maxBytes) {
  std::error_code ec;
  if (!std::filesystem::exists(std::filesystem::symlink_status(path, ec))) {
    return {std::nullopt, "absent"};
  }
  std::string bytes;
  try {
    bytes = readRegularFile(path, maxBytes);
  } catch (const FileReadError& e) {
    return {std::nullopt, fmt::format("{} is not usable ({})", path.string(), e.what())};
  }
  const auto corrupt = [&](std::string_view what) {
    return Lookup{std::nullopt, fmt::format("{} is corrupt ({})", path.string(), what)};
  };
  if (bytes.size() < sizeof(kMagic) + 2 * sizeof(std::uint32_t) ||
      std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    return corrupt("not a LUT file");
  }
  Reader header(std::string_view(bytes).substr(sizeof(kMagic)));
  std::uint32_t version = 0;
  header.value(version);
  if (version != kFormatVersion) {
    return {std::nullopt, fmt::format("{} is stale (format {}, this build reads {})", path.string(),
                                      version, kFormatVersion)};
  }
  const std::string_view body = std::string_view(bytes).substr(0, bytes.size() - 4);
  std::uint32_t storedCrc = 0;
  std::memcpy(&storedCrc, bytes.data() + body.size(), sizeof(storedCrc));
  if (crc(body.data(), body.size()) != storedCrc) return corrupt("checksum mismatch");

  Reader reader(body.substr(sizeof(kMagic) + sizeof(std::uint32_t)));
  std::string storedKey;
  if (!reader.text(storedKey)) return corrupt("bad key");
  if (key && storedKey != *key) {
    return {std::nullopt, fmt::format("{} is stale (built for other inputs)", path.string())};
  }
  PanoramaLut lut;
  std::vector<std::array<std::int32_t, 2>> sizes;
  if (!reader.array(sizes) || sizes.empty() || !reader.array(lut.taps) ||
      !reader.array(lut.blendTaps) || !reader.array(lut.blendRowBegin) || !reader.atEnd()) {
    return corrupt("inconsistent contents");
  }
  lut.size = {sizes[0][0], sizes[0][1]};
  for (std::size_t i = 1; i < sizes.size(); ++i)
    lut.cameraSizes.emplace_back(sizes[i][0], sizes[i][1]);
  if (!consistent(lut)) return corrupt("inconsistent contents");
  return {std::move(lut), {}};
}

void PanoramaLutCache::store(const std::string& key, const PanoramaLut& lut) const {
  Writer writer;
  writer.bytes().append(kMagic, sizeof(kMagic));
  writer.value(kFormatVersion);
  writer.text(key);
  // The panorama's size, then each camera's.
  std::vector<std::array<std::int32_t, 2>> sizes{{lut.size.width, lut.size.height}};
  for (const auto& size : lut.cameraSizes) sizes.push_back({size.width, size.height});
  writer.array(sizes);
  writer.array(lut.taps);
  writer.array(lut.blendTaps);
  writer.array(lut.blendRowBegin);
  writer.value(crc(writer.bytes().data(), writer.bytes().size()));

  const auto path = fileFor(key);
  const auto part = std::filesystem::path(path.string() + ".part");
  std::error_code error;
  std::filesystem::create_directories(folder_, error);
  // Whatever has the temporary name goes first: writing into a FIFO left there would block.
  std::filesystem::remove(part, error);
  {
    std::ofstream file(part, std::ios::binary | std::ios::trunc);
    file.write(writer.bytes().data(), static_cast<std::streamsize>(writer.bytes().size()));
    file.close();
    if (!file) {
      std::filesystem::remove(part, error);
      throw std::runtime_error(fmt::format("cannot write the LUT cache file {}", part.string()));
    }
  }
  std::filesystem::rename(part, path, error);
  if (error) {
    std::filesystem::remove(part, error);
    throw std::runtime_error(
        fmt::format("cannot rename {} to {}: {}", part.string(), path.string(), error.message()));
  }
}

}  // namespace surroundd::processing
