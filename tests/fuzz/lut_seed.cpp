// Writes the LUT cache fuzz target's seeds with the cache's own writer (PanoramaLutCache::store)
// under the target's key: `lut_seed FOLDER`. Two tiny LUTs: one camera, and two cameras with a
// blend tap and an unseen pixel. Run by hand when the format changes; its output is committed in
// corpus/lut_cache/.

#include <cstdio>
#include <filesystem>

#include "processing/stitch/panorama_lut_cache.hpp"

using surroundd::processing::BlendTap;
using surroundd::processing::LutTap;
using surroundd::processing::PanoramaLut;
using surroundd::processing::PanoramaLutCache;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: lut_seed FOLDER\n");
    return 2;
  }
  const std::filesystem::path folder = argv[1];
  PanoramaLut one;
  one.size = {2, 2};
  one.cameraSizes = {{4, 4}};
  one.taps = {{0, 0, 0, 0, 0}, {1, 64, 0, 0, 0}, {4, 0, 64, 0, 0}, {5, 128, 128, 0, 0}};
  one.blendRowBegin = {0, 0, 0};
  PanoramaLut two;
  two.size = {3, 2};
  two.cameraSizes = {{4, 4}, {3, 3}};
  two.taps = {{0, 0, 0, 0, 0},   {1, 10, 20, 1, 0}, {0, 0, 0, PanoramaLut::kUnseen, 0},
              {4, 64, 64, 0, 0}, {3, 0, 0, 1, 0},   {5, 1, 2, 0, 0}};
  two.blendTaps = {{1, {0, 5, 5, 0, 100}}, {4, {2, 0, 0, 0, 30}}};
  two.blendRowBegin = {0, 1, 2};
  for (const auto& [name, lut] : {std::pair{"one-camera", &one}, std::pair{"two-cameras", &two}}) {
    const auto sub = folder / name;
    const PanoramaLutCache cache(sub);
    cache.store("fuzz", *lut);
    if (!cache.load("fuzz", lut->size).lut) {
      std::fprintf(stderr, "lut_seed: the %s LUT does not load back\n", name);
      return 1;
    }
    std::filesystem::rename(cache.fileFor("fuzz"), folder / (std::string(name) + ".lut"));
    std::filesystem::remove(sub);
  }
  return 0;
}
