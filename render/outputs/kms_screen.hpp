#pragma once
// A screen driven through the kernel (DRM/KMS), for a vehicle computer without a desktop:
//   DrmCard    a card this process drives: opened, its DRM master, a GBM device on it (for
//              scan-out buffers, and for EGL's GBM platform: EglPlatform::kGbm);
//   KmsScreen  one of its connectors with its preferred mode and a display controller (CRTC)
//              that can drive it: shows frame buffers, each from the next vertical blank by a page
//              flip, and gives the controller back as it found it.
// The two outputs that use them: DrmDisplaySink (pictures copied into two mapped buffers) and
// EglDisplaySink (views drawn by OpenGL into a GBM surface).
//
// Error policy: RenderError naming the device and what is missing ("no connected connector
// (found: HDMI-A-1 disconnected, DP-1 disconnected)", "cannot become DRM master (another process
// drives the display?)").
// Threading: one thread at a time.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include <opencv2/core/types.hpp>

struct gbm_bo;
struct gbm_device;

namespace surroundd::render {

struct DrmDisplaySettings {
  std::filesystem::path device;  // a card node, e.g. /dev/dri/card0; empty: the first card that
                                 // has the connector
  std::string connector;         // e.g. HDMI-A-1; empty: the first connected one

  bool operator==(const DrmDisplaySettings&) const = default;
};

class DrmCard {
 public:
  // The settings' device, or the first card (/dev/dri/card*, in order) that has the connector
  // connected and can be driven; throws RenderError saying why each could not.
  explicit DrmCard(const DrmDisplaySettings& settings);
  ~DrmCard();
  DrmCard(const DrmCard&) = delete;
  DrmCard& operator=(const DrmCard&) = delete;

  int fd() const { return fd_; }
  gbm_device* gbm() const { return gbm_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  void open(const std::filesystem::path& device, const std::string& connector);
  void close();

  std::filesystem::path path_;
  int fd_ = -1;
  gbm_device* gbm_ = nullptr;
};

class KmsScreen {
 public:
  // The connector named `connector` (empty: the first connected one) of the card open as `fd`,
  // whose DRM master this process is; `card` names it in messages. Shows nothing until show().
  KmsScreen(int fd, std::filesystem::path card, const std::string& connector);
  // The display controller as it was found (and every frame buffer made here removed).
  ~KmsScreen();
  KmsScreen(const KmsScreen&) = delete;
  KmsScreen& operator=(const KmsScreen&) = delete;

  // The mode's size.
  cv::Size size() const;
  // A frame buffer (XRGB8888) showing `bo`, made on the first call for it.
  std::uint32_t framebufferOf(gbm_bo* bo);
  // Shows `framebuffer` from the next vertical blank: the first sets the mode, each later one
  // flips to it once the flip before has completed (waiting for it if need be).
  void show(std::uint32_t framebuffer);
  // Whether the last flip has completed, without waiting; throws RenderError when it has not
  // within 500 ms of its request (the display is gone).
  bool flipped();
  // Waits until the last flip has completed; throws RenderError as flipped() does.
  void finishFlip();
  // "HDMI-A-1 1920x1080@60 on /dev/dri/card0"
  std::string describe() const;

 private:
  struct State;  // keeps libdrm out of the header
  std::unique_ptr<State> state_;
};

}  // namespace surroundd::render
