// The LUT cache loader on any file: a LUT whose invariants hold (so the stitcher cannot read
// outside a camera image), or a problem text; never a crash, an unbounded allocation or UB.
//
// Every cache file ends with a CRC-32 of the rest, which random mutations almost never keep right,
// so the harness writes the input with its CRC set: the parser behind the checksum is what is
// fuzzed. (An input of under 4 bytes is written as it is.) The key is fixed ("fuzz"); the seed
// corpus holds LUTs stored under it by PanoramaLutCache::store.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include <zlib.h>

#include "processing/stitch/panorama_lut_cache.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const surroundd::processing::PanoramaLutCache cache(surroundd::fuzz::scratchFolder());
  static const std::string key = "fuzz";
  std::string bytes(surroundd::fuzz::asText(data, size));
  if (bytes.size() >= 4) {
    const auto body = bytes.size() - 4;
    const auto crc = static_cast<std::uint32_t>(
        crc32_z(crc32_z(0, nullptr, 0), reinterpret_cast<const Bytef*>(bytes.data()), body));
    std::memcpy(bytes.data() + body, &crc, sizeof crc);
  }
  surroundd::fuzz::writeFile(cache.fileFor(key), bytes);
  const auto lookup = cache.load(key, {16384, 8192});  // the largest panorama a config may ask for
  if (lookup.lut) {
    // What the stitcher relies on: a tap per pixel, blend rows that cover the blend taps.
    const auto& lut = *lookup.lut;
    FUZZ_CHECK(lut.taps.size() == static_cast<std::size_t>(lut.size.width) *
                                      static_cast<std::size_t>(lut.size.height));
  }
  return 0;
}
