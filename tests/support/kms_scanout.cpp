#include "tests/support/kms_scanout.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <system_error>

#include <drm_fourcc.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <sys/mman.h>
#include <unistd.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

namespace surroundd::testing {
namespace {

[[noreturn]] void fail(const std::filesystem::path& card, std::string_view what) {
  throw std::runtime_error(fmt::format("scanout of {}: {}: {}", card.string(), what,
                                       std::system_category().message(errno)));
}

struct Card {
  explicit Card(const std::filesystem::path& path) : fd(::open(path.c_str(), O_RDWR | O_CLOEXEC)) {
    if (fd < 0) fail(path, "cannot open");
  }
  ~Card() { ::close(fd); }
  Card(const Card&) = delete;
  Card& operator=(const Card&) = delete;
  int fd;
};

// The pixels of frame buffer `id`, mapped as a dumb buffer (which every GEM object of a
// software-scanned card is) and copied out.
cv::Mat readFramebuffer(const std::filesystem::path& path, int fd, std::uint32_t id) {
  const std::unique_ptr<drmModeFB2, decltype(&drmModeFreeFB2)> fb(drmModeGetFB2(fd, id),
                                                                  drmModeFreeFB2);
  if (!fb) fail(path, "cannot read the frame buffer");
  if (fb->handles[0] == 0) fail(path, "no handle to the frame buffer's memory (not root?)");
  if (fb->pixel_format != DRM_FORMAT_XRGB8888 && fb->pixel_format != DRM_FORMAT_ARGB8888) {
    throw std::runtime_error(fmt::format("scanout of {}: format {:#x}, not 32-bit RGB",
                                         path.string(), fb->pixel_format));
  }
  drm_mode_map_dumb map{};
  map.handle = fb->handles[0];
  if (drmIoctl(fd, DRM_IOCTL_MODE_MAP_DUMB, &map) != 0) fail(path, "cannot map the frame buffer");
  const std::size_t size = static_cast<std::size_t>(fb->pitches[0]) * fb->height;
  void* data = ::mmap(nullptr, size, PROT_READ, MAP_SHARED, fd, static_cast<off_t>(map.offset));
  if (data == MAP_FAILED) fail(path, "cannot map the frame buffer");
  cv::Mat bgr;
  cv::cvtColor(cv::Mat(static_cast<int>(fb->height), static_cast<int>(fb->width), CV_8UC4, data,
                       fb->pitches[0]),
               bgr, cv::COLOR_BGRA2BGR);
  ::munmap(data, size);
  drmCloseBufferHandle(fd, fb->handles[0]);
  return bgr;
}

}  // namespace

std::filesystem::path kmsScreenForTests() {
  const char* card = std::getenv("SURROUNDD_KMS_SCREEN");  // NOLINT(concurrency-mt-unsafe)
  return card != nullptr ? std::filesystem::path(card) : std::filesystem::path();
}

Scanout scanout(const std::filesystem::path& card) {
  const Card open(card);
  const std::unique_ptr<drmModeRes, decltype(&drmModeFreeResources)> resources(
      drmModeGetResources(open.fd), drmModeFreeResources);
  if (!resources) fail(card, "cannot read its resources");
  for (int i = 0; i < resources->count_crtcs; ++i) {
    const std::unique_ptr<drmModeCrtc, decltype(&drmModeFreeCrtc)> crtc(
        drmModeGetCrtc(open.fd, resources->crtcs[i]), drmModeFreeCrtc);
    if (crtc && crtc->buffer_id != 0) {
      return {crtc->buffer_id, readFramebuffer(card, open.fd, crtc->buffer_id)};
    }
  }
  return {};
}

cv::Rect fittedPlace(cv::Size picture, cv::Size screen) {
  const double scale = std::min(static_cast<double>(screen.width) / picture.width,
                                static_cast<double>(screen.height) / picture.height);
  const cv::Size fitted(static_cast<int>(picture.width * scale),
                        static_cast<int>(picture.height * scale));
  return {(screen.width - fitted.width) / 2, (screen.height - fitted.height) / 2, fitted.width,
          fitted.height};
}

ShownAgainst compareShown(const cv::Mat& shown, const cv::Mat& expected, const cv::Rect& area) {
  cv::Mat around = shown.clone();
  around(area).setTo(cv::Scalar::all(0));
  return {cv::norm(shown(area), expected, cv::NORM_INF), cv::countNonZero(around.reshape(1))};
}

}  // namespace surroundd::testing
