#pragma once
// What the fuzz targets share: a private scratch folder for inputs that must be files, and quiet
// logging (a target that logs each input runs a hundred times slower).

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <span>
#include <string>
#include <string_view>

#include <spdlog/spdlog.h>

namespace surroundd::fuzz {

// A folder of this process's own under $TMPDIR (libFuzzer's -fork/-jobs run several at once),
// removed at exit.
inline const std::filesystem::path& scratchFolder() {
  static const std::filesystem::path folder = [] {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "surroundd-fuzz-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) std::abort();
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(scratchFolder(), ignored);
    });
    return std::filesystem::path(pattern);
  }();
  return folder;
}

// A promise of the code under test that an input broke: says which, then aborts, so that libFuzzer
// keeps the input as a finding.
[[noreturn]] inline void brokenPromise(const char* promise, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: broken: %s\n", file, line, promise);
  std::abort();
}

inline void quietLogs() { spdlog::set_level(spdlog::level::off); }

// A stream that drops what a command prints (its log of what it did).
inline std::ostream& discardedLog() {
  static std::ostream nowhere(nullptr);
  return nowhere;
}

inline std::string_view asText(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

inline void writeFile(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!file) std::abort();  // the harness's own failure, not the code's
}

}  // namespace surroundd::fuzz

// FUZZ_CHECK(what the code promises), in the spirit of gtest's EXPECT_ but fatal: a fuzz target
// has one input at a time and nothing to go on with. (A macro, for the promise's own text.)
#define FUZZ_CHECK(promise) \
  ((promise) ? (void)0 : ::surroundd::fuzz::brokenPromise(#promise, __FILE__, __LINE__))
