#include "common/regular_file.hpp"

#include <array>
#include <cerrno>
#include <system_error>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace surroundd {
namespace {

std::string kindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// Opens without blocking (a FIFO with no writer would wait forever) and checks what the
// descriptor is: a path checked first could be swapped before it is opened.
class OpenFile {
 public:
  OpenFile(const std::filesystem::path& path, std::size_t maxBytes)
      : fd_(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)) {
    if (fd_ < 0) {
      problem_ = errno == ENOENT ? "it does not exist" : std::system_category().message(errno);
      return;
    }
    struct stat status {};
    if (::fstat(fd_, &status) != 0) {
      problem_ = std::system_category().message(errno);
    } else if (!S_ISREG(status.st_mode)) {
      problem_ = kindOf(status.st_mode) + ", not a file";
    } else if (static_cast<std::size_t>(status.st_size) > maxBytes) {
      problem_ = "larger than " + std::to_string(maxBytes) + " bytes (" +
                 std::to_string(status.st_size) + ")";
    } else {
      size_ = static_cast<std::size_t>(status.st_size);
    }
  }
  ~OpenFile() {
    if (fd_ >= 0) ::close(fd_);
  }
  OpenFile(const OpenFile&) = delete;
  OpenFile& operator=(const OpenFile&) = delete;

  const std::string& problem() const { return problem_; }
  int fd() const { return fd_; }
  std::size_t size() const { return size_; }

 private:
  int fd_;
  std::string problem_;
  std::size_t size_ = 0;
};

}  // namespace

std::string regularFileProblem(const std::filesystem::path& path, std::size_t maxBytes) {
  return OpenFile(path, maxBytes).problem();
}

std::string readRegularFile(const std::filesystem::path& path, std::size_t maxBytes) {
  const OpenFile file(path, maxBytes);
  if (!file.problem().empty()) throw FileReadError(path.string() + ": " + file.problem());
  // Read to the end, within the bound: a file that grows while it is read is refused at the
  // bound rather than read forever.
  std::string bytes;
  bytes.reserve(file.size());
  std::array<char, 65536> chunk{};
  for (;;) {
    const ssize_t got = ::read(file.fd(), chunk.data(), chunk.size());
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) throw FileReadError(path.string() + ": " + std::system_category().message(errno));
    if (got == 0) return bytes;
    if (bytes.size() + static_cast<std::size_t>(got) > maxBytes) {
      throw FileReadError(path.string() + ": larger than " + std::to_string(maxBytes) + " bytes");
    }
    bytes.append(chunk.data(), static_cast<std::size_t>(got));
  }
}

}  // namespace surroundd
