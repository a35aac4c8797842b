#pragma once
// Reading a file the daemon is given (a config, a rig, a mask picture, a cached LUT) without
// trusting what the path is: it must be a regular file (after symlinks) and no larger than the
// reader's bound. A FIFO would block open() forever, /dev/zero never ends, a directory fails
// deep inside a stream with no name; each is refused here, naming the file and what it is.

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace surroundd {

class FileReadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The whole file. Throws FileReadError ("<path>: <what is wrong>") for anything but a readable
// regular file of at most maxBytes bytes.
std::string readRegularFile(const std::filesystem::path& path, std::size_t maxBytes);

// Why `path` cannot be read as a regular file of at most maxBytes bytes ("" when it can), without
// reading it: for readers that take a path themselves (cv::imread).
std::string regularFileProblem(const std::filesystem::path& path, std::size_t maxBytes);

}  // namespace surroundd
