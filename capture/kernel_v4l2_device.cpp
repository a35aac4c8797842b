#include <cerrno>

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include "capture/v4l2_device.hpp"

namespace surroundd::capture {
namespace {

class KernelV4l2Device final : public V4l2Device {
 public:
  ~KernelV4l2Device() override { close(); }

  int open(const std::string& path) override {
    close();
    fd_ = ::open(path.c_str(),
                 O_RDWR | O_NONBLOCK | O_CLOEXEC);  // NOLINT(cppcoreguidelines-pro-type-vararg)
    return fd_ < 0 ? errno : 0;
  }

  void close() override {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

  int ioctl(unsigned long request, void* argument) override {
    int result = 0;
    do {
      result = ::ioctl(fd_, request, argument);  // NOLINT(cppcoreguidelines-pro-type-vararg)
    } while (result < 0 && errno == EINTR);
    return result < 0 ? errno : 0;
  }

  void* map(std::size_t length, std::int64_t offset) override {
    void* address = ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, offset);
    return address == MAP_FAILED ? nullptr : address;
  }

  void unmap(void* address, std::size_t length) override { ::munmap(address, length); }

  int waitReadable(std::chrono::milliseconds timeout) override {
    pollfd entry{fd_, POLLIN, 0};
    int ready = 0;
    do {
      ready = ::poll(&entry, 1, static_cast<int>(timeout.count()));
    } while (ready < 0 && errno == EINTR);
    if (ready < 0) return errno;
    if (ready == 0) return ETIMEDOUT;
    if ((entry.revents & (POLLERR | POLLHUP | POLLNVAL)) != 0) return ENODEV;
    return 0;
  }

 private:
  int fd_ = -1;
};

}  // namespace

std::unique_ptr<V4l2Device> makeKernelV4l2Device() { return std::make_unique<KernelV4l2Device>(); }

}  // namespace surroundd::capture
