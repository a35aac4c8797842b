#pragma once
// The picture on a display driven by the kernel (DRM/KMS), for a vehicle computer without a
// desktop: surroundd becomes the DRM master of the card, sets the connector's preferred mode and
// flips between two scan-out buffers allocated through GBM (linear XRGB8888, mapped once). Each
// frame is scaled into the back buffer to fill the mode, keeping its aspect (black bars), and shown
// at the next vertical blank; the CRTC's previous configuration is restored at the end.
//
// Error policy: the constructor throws RenderError naming the device and what is missing ("no
// connected connector (found: HDMI-A-1 disconnected, DP-1 disconnected)", "cannot become DRM
// master: another process drives the display"); consume() throws RenderError when a page flip
// fails, which ends this output.
// Threading: used from the pipeline thread only.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "render/outputs/frame_sink.hpp"

namespace surroundd::render {

struct DrmDisplaySettings {
  std::filesystem::path device;  // a card node, e.g. /dev/dri/card0; empty: the first card that
                                 // has a connected connector
  std::string connector;         // e.g. HDMI-A-1; empty: the first connected one

  bool operator==(const DrmDisplaySettings&) const = default;
};

class DrmDisplaySink final : public FrameSink {
 public:
  explicit DrmDisplaySink(const DrmDisplaySettings& settings);
  ~DrmDisplaySink() override;

  void consume(const cv::Mat& bgr, const PictureTime& time) override;
  void finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) override;
  // "display HDMI-A-1 1920x1080@60 on /dev/dri/card0 (123 frames)"
  std::string describe() const override;

 private:
  struct Card;  // the open card, the mode and the buffers (keeps libdrm and GBM out of the header)
  std::unique_ptr<Card> card_;
  std::uint64_t frames_ = 0;
};

}  // namespace surroundd::render
