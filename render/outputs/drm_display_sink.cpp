#include "render/outputs/drm_display_sink.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <system_error>
#include <vector>

#include <fcntl.h>
#include <fmt/format.h>
#include <gbm.h>
#include <opencv2/imgproc.hpp>
#include <poll.h>
#include <unistd.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#include "render/render_error.hpp"

namespace surroundd::render {
namespace {

// A flip that has not completed after this long means the display is gone.
constexpr int kFlipTimeoutMs = 500;

std::string errnoText() { return std::system_category().message(errno); }

template <typename T, void (*Free)(T*)>
struct Freed {
  void operator()(T* pointer) const noexcept { Free(pointer); }
};
using Resources = std::unique_ptr<drmModeRes, Freed<drmModeRes, drmModeFreeResources>>;
using Connector = std::unique_ptr<drmModeConnector, Freed<drmModeConnector, drmModeFreeConnector>>;
using Encoder = std::unique_ptr<drmModeEncoder, Freed<drmModeEncoder, drmModeFreeEncoder>>;
using Crtc = std::unique_ptr<drmModeCrtc, Freed<drmModeCrtc, drmModeFreeCrtc>>;
using GbmDevice = std::unique_ptr<gbm_device, Freed<gbm_device, gbm_device_destroy>>;

std::string connectorName(const drmModeConnector& connector) {
  const char* type = drmModeGetConnectorTypeName(connector.connector_type);
  return fmt::format("{}-{}", type != nullptr ? type : "unknown", connector.connector_type_id);
}

}  // namespace

struct DrmDisplaySink::Card {
  struct Buffer {
    gbm_bo* bo = nullptr;
    std::uint32_t framebuffer = 0;
    void* mapping = nullptr;
    cv::Mat pixels;  // BGRX over the mapping
  };

  std::filesystem::path path;
  int fd = -1;
  GbmDevice gbm;
  std::string connectorName;
  std::uint32_t connectorId = 0;
  std::uint32_t crtcId = 0;
  drmModeModeInfo mode{};
  Crtc savedCrtc;
  std::array<Buffer, 2> buffers;
  std::size_t back = 0;
  bool flipPending = false;
  bool modeSet = false;
  cv::Mat scaled;  // a picture scaled to the mode, before it is widened into the back buffer

  [[noreturn]] void fail(std::string_view what) const {
    throw RenderError(fmt::format("display {}: {}", path.string(), what));
  }

  ~Card() {
    if (flipPending) waitForFlip();  // a display that is gone is no reason not to clean up
    if (savedCrtc && modeSet) {
      drmModeSetCrtc(fd, savedCrtc->crtc_id, savedCrtc->buffer_id, savedCrtc->x, savedCrtc->y,
                     &connectorId, 1, &savedCrtc->mode);
    }
    for (auto& buffer : buffers) {
      if (buffer.framebuffer != 0) drmModeRmFB(fd, buffer.framebuffer);
      if (buffer.mapping != nullptr) gbm_bo_unmap(buffer.bo, buffer.mapping);
      if (buffer.bo != nullptr) gbm_bo_destroy(buffer.bo);
    }
    gbm.reset();
    if (fd >= 0) {
      drmDropMaster(fd);
      ::close(fd);
    }
  }

  void open(const std::filesystem::path& device) {
    path = device;
    fd = ::open(device.c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0) fail(fmt::format("cannot open: {}", errnoText()));
    if (!drmIsKMS(fd)) fail("not a KMS display device (a render node, or not DRM at all)");
  }

  // The connector to drive, with its preferred mode and a CRTC that can drive it.
  void chooseOutput(const std::string& wanted) {
    const Resources resources(drmModeGetResources(fd));
    if (!resources) fail(fmt::format("cannot read its resources: {}", errnoText()));
    std::string found;
    for (int i = 0; i < resources->count_connectors; ++i) {
      const Connector connector(drmModeGetConnector(fd, resources->connectors[i]));
      if (!connector) continue;
      const std::string name = surroundd::render::connectorName(*connector);
      const bool connected =
          connector->connection == DRM_MODE_CONNECTED && connector->count_modes > 0;
      found += fmt::format("{}{} {}", found.empty() ? "" : ", ", name,
                           connected ? "connected" : "disconnected");
      if (!connected || (!wanted.empty() && name != wanted)) continue;
      const auto* preferred = std::find_if(
          connector->modes, connector->modes + connector->count_modes,
          [](const drmModeModeInfo& m) { return (m.type & DRM_MODE_TYPE_PREFERRED) != 0; });
      mode =
          preferred != connector->modes + connector->count_modes ? *preferred : connector->modes[0];
      connectorId = connector->connector_id;
      connectorName = name;
      crtcId = crtcFor(*resources, *connector);
      if (crtcId == 0) fail(fmt::format("no display controller can drive {}", name));
      return;
    }
    fail(wanted.empty() ? fmt::format("no connected connector (found: {})", found)
                        : fmt::format("no connected connector '{}' (found: {})", wanted, found));
  }

  std::uint32_t crtcFor(const drmModeRes& resources, const drmModeConnector& connector) const {
    for (int e = 0; e < connector.count_encoders; ++e) {
      const Encoder encoder(drmModeGetEncoder(fd, connector.encoders[e]));
      if (!encoder) continue;
      if (encoder->crtc_id != 0) return encoder->crtc_id;  // the one it is on already
      for (int c = 0; c < resources.count_crtcs; ++c) {
        if ((encoder->possible_crtcs & (1U << static_cast<unsigned>(c))) != 0) {
          return resources.crtcs[c];
        }
      }
    }
    return 0;
  }

  void allocateBuffers() {
    gbm.reset(gbm_create_device(fd));
    if (!gbm) fail("cannot create a GBM device");
    for (auto& buffer : buffers) {
      buffer.bo = gbm_bo_create(gbm.get(), mode.hdisplay, mode.vdisplay, GBM_FORMAT_XRGB8888,
                                GBM_BO_USE_SCANOUT | GBM_BO_USE_LINEAR);
      if (buffer.bo == nullptr) {
        fail(fmt::format("cannot allocate a {}x{} scan-out buffer", mode.hdisplay, mode.vdisplay));
      }
      const std::array<std::uint32_t, 4> handles{gbm_bo_get_handle(buffer.bo).u32, 0, 0, 0};
      const std::array<std::uint32_t, 4> pitches{gbm_bo_get_stride(buffer.bo), 0, 0, 0};
      const std::array<std::uint32_t, 4> offsets{};
      if (drmModeAddFB2(fd, mode.hdisplay, mode.vdisplay, GBM_FORMAT_XRGB8888, handles.data(),
                        pitches.data(), offsets.data(), &buffer.framebuffer, 0) != 0) {
        fail(fmt::format("cannot make a frame buffer: {}", errnoText()));
      }
      // Mapped once for the sink's life: writing a frame is then a plain memory copy.
      std::uint32_t stride = 0;
      void* data = gbm_bo_map(buffer.bo, 0, 0, mode.hdisplay, mode.vdisplay, GBM_BO_TRANSFER_WRITE,
                              &stride, &buffer.mapping);
      if (data == nullptr) fail("cannot map a scan-out buffer");
      buffer.pixels = cv::Mat(mode.vdisplay, mode.hdisplay, CV_8UC4, data, stride);
      buffer.pixels.setTo(cv::Scalar::all(0));
    }
  }

  void setMode() {
    if (drmSetMaster(fd) != 0) {
      fail(fmt::format("cannot become DRM master (another process drives the display?): {}",
                       errnoText()));
    }
    savedCrtc.reset(drmModeGetCrtc(fd, crtcId));
    if (drmModeSetCrtc(fd, crtcId, buffers[0].framebuffer, 0, 0, &connectorId, 1, &mode) != 0) {
      fail(fmt::format("cannot set {}x{}@{} on {}: {}", mode.hdisplay, mode.vdisplay, mode.vrefresh,
                       connectorName, errnoText()));
    }
    modeSet = true;
    back = 1;
  }

  // False when the flip did not complete in time (the display is gone).
  bool waitForFlip() {
    drmEventContext events{};
    events.version = 2;
    events.page_flip_handler = [](int, unsigned, unsigned, unsigned, void* data) {
      *static_cast<bool*>(data) = false;
    };
    while (flipPending) {
      pollfd ready{fd, POLLIN, 0};
      if (::poll(&ready, 1, kFlipTimeoutMs) <= 0) {
        flipPending = false;
        return false;
      }
      drmHandleEvent(fd, &events);
    }
    return true;
  }

  void finishFlip() {
    if (flipPending && !waitForFlip()) fail("the display did not complete a page flip");
  }
};

DrmDisplaySink::DrmDisplaySink(const DrmDisplaySettings& settings) {
  std::vector<std::filesystem::path> candidates;
  if (!settings.device.empty()) {
    candidates.push_back(settings.device);
  } else {
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator("/dev/dri", error)) {
      if (entry.path().filename().string().starts_with("card")) candidates.push_back(entry.path());
    }
    std::ranges::sort(candidates);
    if (candidates.empty())
      throw RenderError("display: no DRM card (/dev/dri/card*) on this machine");
  }
  std::string reasons;
  for (const auto& device : candidates) {
    try {
      auto card = std::make_unique<Card>();
      card->open(device);
      card->chooseOutput(settings.connector);
      card->allocateBuffers();
      card->setMode();
      card_ = std::move(card);
      return;
    } catch (const RenderError& e) {
      if (candidates.size() == 1) throw;
      reasons += fmt::format("{}{}", reasons.empty() ? "" : "; ", e.what());
    }
  }
  throw RenderError(fmt::format("display: no card could show the picture ({})", reasons));
}

DrmDisplaySink::~DrmDisplaySink() = default;

void DrmDisplaySink::consume(const cv::Mat& bgr, const PictureTime& /*time*/) {
  auto& card = *card_;
  if (bgr.type() != CV_8UC3) card.fail("expected an 8-bit BGR picture");
  card.finishFlip();  // the back buffer is free once the previous flip has shown the other one
  auto& buffer = card.buffers[card.back];
  const cv::Size target = buffer.pixels.size();
  const double scale = std::min(static_cast<double>(target.width) / bgr.cols,
                                static_cast<double>(target.height) / bgr.rows);
  const cv::Size fitted(static_cast<int>(bgr.cols * scale), static_cast<int>(bgr.rows * scale));
  const cv::Rect area((target.width - fitted.width) / 2, (target.height - fitted.height) / 2,
                      fitted.width, fitted.height);
  cv::Mat region = buffer.pixels(area);  // written in place: cvtColor keeps its size and type
  if (fitted == bgr.size()) {
    cv::cvtColor(bgr, region, cv::COLOR_BGR2BGRA);
  } else {
    cv::resize(bgr, card.scaled, fitted, 0, 0, cv::INTER_LINEAR);  // allocated on the first frame
    cv::cvtColor(card.scaled, region, cv::COLOR_BGR2BGRA);
  }
  if (drmModePageFlip(card.fd, card.crtcId, buffer.framebuffer, DRM_MODE_PAGE_FLIP_EVENT,
                      &card.flipPending) != 0) {
    card.fail(fmt::format("page flip failed: {}", errnoText()));
  }
  card.flipPending = true;
  card.back = 1 - card.back;
  ++frames_;
}

void DrmDisplaySink::finish(const cv::Mat& /*lastFrame*/, std::chrono::nanoseconds /*lastTime*/) {
  card_->finishFlip();
}

std::string DrmDisplaySink::describe() const {
  const auto& card = *card_;
  return fmt::format("display {} {}x{}@{} on {} ({} frames)", card.connectorName,
                     card.mode.hdisplay, card.mode.vdisplay, card.mode.vrefresh, card.path.string(),
                     frames_);
}

}  // namespace surroundd::render
