#pragma once
// A small disk of its own for a test that fills one: a tmpfs of `bytes` mounted on a fresh folder
// (root only: a test skips, saying why, where it cannot mount), unmounted with all it holds
// afterwards. fill() leaves a given number of bytes free; empty() gives the room back.

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <sys/mount.h>

#include "tests/support/temp_dir.hpp"

namespace surroundd::testing {

class SmallDisk {
 public:
  explicit SmallDisk(std::uintmax_t bytes) : root_(folder_ / "disk") {
    std::filesystem::create_directories(root_);
    const std::string options = "size=" + std::to_string(bytes);
    if (::mount("tmpfs", root_.c_str(), "tmpfs", MS_NOSUID | MS_NODEV, options.c_str()) != 0) {
      problem_ = std::string("cannot mount a small tmpfs to fill (") + std::strerror(errno) +
                 "; the test needs root)";
    }
  }
  ~SmallDisk() {
    if (problem_.empty()) ::umount2(root_.c_str(), MNT_DETACH);
  }
  SmallDisk(const SmallDisk&) = delete;
  SmallDisk& operator=(const SmallDisk&) = delete;

  // Why there is no disk ("" when there is): the test skips with it.
  const std::string& problem() const { return problem_; }
  std::filesystem::path operator/(const std::string& name) const { return root_ / name; }

  std::uintmax_t available() const { return std::filesystem::space(root_).available; }
  // Writes a filler file that leaves about `free` bytes of the disk free.
  void fill(std::uintmax_t free) {
    const std::uintmax_t now = available();
    if (now <= free) return;
    std::ofstream filler(root_ / ("filler-" + std::to_string(fillers_++)), std::ios::binary);
    const std::vector<char> block(1 << 16, 'x');
    for (std::uintmax_t left = now - free; left > 0;) {
      const auto size = static_cast<std::streamsize>(std::min<std::uintmax_t>(left, block.size()));
      filler.write(block.data(), size);
      left -= static_cast<std::uintmax_t>(size);
    }
  }
  // Removes what fill() wrote.
  void empty() {
    for (int i = 0; i < fillers_; ++i)
      std::filesystem::remove(root_ / ("filler-" + std::to_string(i)));
    fillers_ = 0;
  }

 private:
  TempDir folder_;
  std::filesystem::path root_;
  std::string problem_;
  int fillers_ = 0;
};

}  // namespace surroundd::testing
