// A fuzz target's main() where there is no libFuzzer (the gcc builds): its function once over
// each seed file given, or each file in a folder given, as libFuzzer's -runs=0 does. So every
// target compiles in every test build, and the ci and ASan + UBSan suites run its seeds; the
// clang `fuzz` preset (scripts/fuzz.sh) is for fuzzing itself.

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "common/regular_file.hpp"

// Seeds are small; one past this is not one (libFuzzer's own default -max_len is 4 KiB).
constexpr std::size_t kMaxSeedBytes = std::size_t{64} << 20;

// NOLINTNEXTLINE(readability-identifier-naming): libFuzzer's interface names them.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);
// Defined by the targets that set up something first.
// NOLINTNEXTLINE(readability-identifier-naming)
extern "C" __attribute__((weak)) int LLVMFuzzerInitialize(int* argc, char*** argv);

int main(int argc, char** argv) {
  if (LLVMFuzzerInitialize != nullptr) LLVMFuzzerInitialize(&argc, &argv);
  std::vector<std::filesystem::path> seeds;
  for (int i = 1; i < argc; ++i) {
    const std::filesystem::path given(argv[i]);
    if (!std::filesystem::is_directory(given)) {
      seeds.push_back(given);
      continue;
    }
    for (const auto& entry : std::filesystem::directory_iterator(given)) {
      if (entry.is_regular_file()) seeds.push_back(entry.path());
    }
  }
  std::ranges::sort(seeds);
  for (const auto& seed : seeds) {
    std::string bytes;
    try {
      bytes = surroundd::readRegularFile(seed, kMaxSeedBytes);
    } catch (const surroundd::FileReadError& error) {
      std::fprintf(stderr, "%s\n", error.what());
      return 1;
    }
    std::fprintf(stderr, "%s (%zu bytes)\n", seed.c_str(), bytes.size());
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  }
  std::printf("%zu seeds, no finding\n", seeds.size());
  return seeds.empty() ? 1 : 0;
}
