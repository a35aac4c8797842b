#pragma once
// PanoramaLuts on disk, so that a restart does not rebuild them.
//
// A LUT is stored under a key that spells out everything it depends on (every camera's lens and
// pose, the panorama settings, this code's format version), as exact text; the file name carries
// a checksum of the key and the file holds the whole key, so a file for other inputs is never
// taken for this one. The payload ends with a CRC-32: a truncated or damaged file is reported as
// corrupt, a file from other inputs or another format version as stale; either way the caller
// rebuilds and stores a new one. Files are written to a temporary name and renamed, so a crash
// never leaves half a LUT under the real name. The format is the machine's own (native byte
// order): a cache belongs to one machine.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "processing/stitch/panorama_lut.hpp"

namespace surroundd::processing {

std::string panoramaLutKey(const Rig& rig, const PanoramaSettings& settings);

class PanoramaLutCache {
 public:
  explicit PanoramaLutCache(std::filesystem::path folder) : folder_(std::move(folder)) {}

  std::filesystem::path fileFor(const std::string& key) const;

  struct Lookup {
    std::optional<PanoramaLut> lut;
    std::string problem;  // when there is no LUT: "absent", or why the file was not usable
  };
  // The LUT stored for `key`, a panorama of `panorama` pixels: a file larger than such a LUT can
  // be is refused before it is read (a sparse 2.9 GB file was read whole: 3.1 GB resident, the
  // first picture after 19 s).
  Lookup load(const std::string& key, cv::Size panorama) const;
  // A LUT file whatever inputs it was built for (its key is not checked; its checksum and
  // contents are): one carried to another machine of the same byte order.
  static Lookup loadFile(const std::filesystem::path& file);

  // Creates the folder if needed. Throws std::runtime_error naming the file when it cannot write.
  void store(const std::string& key, const PanoramaLut& lut) const;

 private:
  static Lookup read(const std::filesystem::path& path, std::optional<std::string_view> key,
                     std::size_t maxBytes);

  std::filesystem::path folder_;
};

}  // namespace surroundd::processing
