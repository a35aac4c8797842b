#include "render/outputs/kms_screen.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <map>
#include <system_error>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <fmt/format.h>
#include <gbm.h>
#include <poll.h>
#include <unistd.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#include "render/render_error.hpp"

namespace surroundd::render {
namespace {

// A flip that has not completed after this long means the display is gone.
constexpr auto kFlipTimeout = std::chrono::milliseconds(500);

std::string errnoText() { return std::system_category().message(errno); }

[[noreturn]] void fail(const std::filesystem::path& card, std::string_view what) {
  throw RenderError(fmt::format("display {}: {}", card.string(), what));
}

template <typename T, void (*Free)(T*)>
struct Freed {
  void operator()(T* pointer) const noexcept { Free(pointer); }
};
using Resources = std::unique_ptr<drmModeRes, Freed<drmModeRes, drmModeFreeResources>>;
using Connector = std::unique_ptr<drmModeConnector, Freed<drmModeConnector, drmModeFreeConnector>>;
using Encoder = std::unique_ptr<drmModeEncoder, Freed<drmModeEncoder, drmModeFreeEncoder>>;
using Crtc = std::unique_ptr<drmModeCrtc, Freed<drmModeCrtc, drmModeFreeCrtc>>;

std::string connectorName(const drmModeConnector& connector) {
  const char* type = drmModeGetConnectorTypeName(connector.connector_type);
  return fmt::format("{}-{}", type != nullptr ? type : "unknown", connector.connector_type_id);
}

std::uint32_t crtcFor(int fd, const drmModeRes& resources, const drmModeConnector& connector) {
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

// What a screen drives: the connector, its preferred mode and a CRTC that can drive it.
struct Output {
  std::string name;
  std::uint32_t connector = 0;
  std::uint32_t crtc = 0;
  drmModeModeInfo mode{};
};

Output findOutput(int fd, const std::filesystem::path& card, const std::string& wanted) {
  const Resources resources(drmModeGetResources(fd));
  if (!resources) fail(card, fmt::format("cannot read its resources: {}", errnoText()));
  std::string found;
  for (int i = 0; i < resources->count_connectors; ++i) {
    const Connector connector(drmModeGetConnector(fd, resources->connectors[i]));
    if (!connector) continue;
    const std::string name = connectorName(*connector);
    const bool connected =
        connector->connection == DRM_MODE_CONNECTED && connector->count_modes > 0;
    found += fmt::format("{}{} {}", found.empty() ? "" : ", ", name,
                         connected ? "connected" : "disconnected");
    if (!connected || (!wanted.empty() && name != wanted)) continue;
    const auto* modes = connector->modes;
    const auto* preferred = std::find_if(
        modes, modes + connector->count_modes,
        [](const drmModeModeInfo& m) { return (m.type & DRM_MODE_TYPE_PREFERRED) != 0; });
    Output output{name, connector->connector_id, crtcFor(fd, *resources, *connector),
                  preferred != modes + connector->count_modes ? *preferred : modes[0]};
    if (output.crtc == 0) fail(card, fmt::format("no display controller can drive {}", name));
    return output;
  }
  fail(card, wanted.empty()
                 ? fmt::format("no connected connector (found: {})", found)
                 : fmt::format("no connected connector '{}' (found: {})", wanted, found));
}

}  // namespace

DrmCard::DrmCard(const DrmDisplaySettings& settings) {
  std::vector<std::filesystem::path> candidates;
  if (!settings.device.empty()) {
    candidates.push_back(settings.device);
  } else {
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator("/dev/dri", error)) {
      if (entry.path().filename().string().starts_with("card")) candidates.push_back(entry.path());
    }
    std::ranges::sort(candidates);
    if (candidates.empty()) {
      throw RenderError("display: no DRM card (/dev/dri/card*) on this machine");
    }
  }
  std::string reasons;
  for (const auto& device : candidates) {
    try {
      open(device, settings.connector);
      return;
    } catch (const RenderError& e) {
      close();
      if (candidates.size() == 1) throw;
      reasons += fmt::format("{}{}", reasons.empty() ? "" : "; ", e.what());
    }
  }
  throw RenderError(fmt::format("display: no card could show the picture ({})", reasons));
}

DrmCard::~DrmCard() { close(); }

void DrmCard::open(const std::filesystem::path& device, const std::string& connector) {
  path_ = device;
  fd_ = ::open(device.c_str(), O_RDWR | O_CLOEXEC);
  if (fd_ < 0) fail(path_, fmt::format("cannot open: {}", errnoText()));
  if (!drmIsKMS(fd_)) fail(path_, "not a KMS display device (a render node, or not DRM at all)");
  findOutput(fd_, path_, connector);  // a card without the screen is not the one
  if (drmSetMaster(fd_) != 0) {
    fail(path_, fmt::format("cannot become DRM master (another process drives the display?): {}",
                            errnoText()));
  }
  gbm_ = gbm_create_device(fd_);
  if (gbm_ == nullptr) fail(path_, "cannot create a GBM device");
}

void DrmCard::close() {
  if (gbm_ != nullptr) gbm_device_destroy(gbm_);
  gbm_ = nullptr;
  if (fd_ >= 0) {
    drmDropMaster(fd_);
    ::close(fd_);
  }
  fd_ = -1;
}

struct KmsScreen::State {
  int fd = -1;
  std::filesystem::path card;
  Output output;
  Crtc saved;
  std::map<gbm_bo*, std::uint32_t> framebuffers;
  bool modeSet = false;
  bool flipPending = false;
  std::chrono::steady_clock::time_point flipAsked;

  // Reads the card's events without waiting longer than `timeout`.
  void readEvents(std::chrono::milliseconds timeout) {
    pollfd ready{fd, POLLIN, 0};
    if (::poll(&ready, 1, static_cast<int>(timeout.count())) <= 0) return;
    drmEventContext events{};
    events.version = 2;
    events.page_flip_handler = [](int, unsigned, unsigned, unsigned, void* pending) {
      *static_cast<bool*>(pending) = false;
    };
    drmHandleEvent(fd, &events);
  }
};

KmsScreen::KmsScreen(int fd, std::filesystem::path card, const std::string& connector)
    : state_(std::make_unique<State>()) {
  state_->fd = fd;
  state_->card = std::move(card);
  state_->output = findOutput(fd, state_->card, connector);
  state_->saved.reset(drmModeGetCrtc(fd, state_->output.crtc));
}

KmsScreen::~KmsScreen() {
  auto& s = *state_;
  // A display that is gone is no reason not to clean up.
  const auto deadline = std::chrono::steady_clock::now() + kFlipTimeout;
  while (s.flipPending && std::chrono::steady_clock::now() < deadline) s.readEvents(kFlipTimeout);
  if (s.saved && s.modeSet) {
    drmModeSetCrtc(s.fd, s.saved->crtc_id, s.saved->buffer_id, s.saved->x, s.saved->y,
                   &s.output.connector, 1, &s.saved->mode);
  }
  for (const auto& [bo, framebuffer] : s.framebuffers) drmModeRmFB(s.fd, framebuffer);
}

cv::Size KmsScreen::size() const {
  return {state_->output.mode.hdisplay, state_->output.mode.vdisplay};
}

std::uint32_t KmsScreen::framebufferOf(gbm_bo* bo) {
  auto& s = *state_;
  if (const auto known = s.framebuffers.find(bo); known != s.framebuffers.end()) {
    return known->second;
  }
  const std::array<std::uint32_t, 4> handles{gbm_bo_get_handle(bo).u32, 0, 0, 0};
  const std::array<std::uint32_t, 4> pitches{gbm_bo_get_stride(bo), 0, 0, 0};
  const std::array<std::uint32_t, 4> offsets{};
  std::uint32_t framebuffer = 0;
  if (drmModeAddFB2(s.fd, gbm_bo_get_width(bo), gbm_bo_get_height(bo), GBM_FORMAT_XRGB8888,
                    handles.data(), pitches.data(), offsets.data(), &framebuffer, 0) != 0) {
    fail(s.card, fmt::format("cannot make a frame buffer: {}", errnoText()));
  }
  s.framebuffers.emplace(bo, framebuffer);
  return framebuffer;
}

void KmsScreen::show(std::uint32_t framebuffer) {
  auto& s = *state_;
  if (!s.modeSet) {
    auto& mode = s.output.mode;
    if (drmModeSetCrtc(s.fd, s.output.crtc, framebuffer, 0, 0, &s.output.connector, 1, &mode) !=
        0) {
      fail(s.card, fmt::format("cannot set {}x{}@{} on {}: {}", mode.hdisplay, mode.vdisplay,
                               mode.vrefresh, s.output.name, errnoText()));
    }
    s.modeSet = true;
    return;
  }
  finishFlip();
  if (drmModePageFlip(s.fd, s.output.crtc, framebuffer, DRM_MODE_PAGE_FLIP_EVENT, &s.flipPending) !=
      0) {
    fail(s.card, fmt::format("page flip failed: {}", errnoText()));
  }
  s.flipPending = true;
  s.flipAsked = std::chrono::steady_clock::now();
}

bool KmsScreen::flipped() {
  auto& s = *state_;
  if (s.flipPending) s.readEvents(std::chrono::milliseconds(0));
  if (s.flipPending && std::chrono::steady_clock::now() - s.flipAsked > kFlipTimeout) {
    s.flipPending = false;
    fail(s.card, "the display did not complete a page flip");
  }
  return !s.flipPending;
}

void KmsScreen::finishFlip() {
  auto& s = *state_;
  while (!flipped()) {
    const auto left = kFlipTimeout - (std::chrono::steady_clock::now() - s.flipAsked);
    s.readEvents(
        std::max(std::chrono::ceil<std::chrono::milliseconds>(left), std::chrono::milliseconds(1)));
  }
}

std::string KmsScreen::describe() const {
  const auto& s = *state_;
  return fmt::format("{} {}x{}@{} on {}", s.output.name, s.output.mode.hdisplay,
                     s.output.mode.vdisplay, s.output.mode.vrefresh, s.card.string());
}

}  // namespace surroundd::render
