#pragma once
// The picture on a display driven by the kernel (DRM/KMS, kms_screen.hpp), for a vehicle computer
// without a desktop: surroundd becomes the DRM master of the card, sets the connector's preferred
// mode and flips between two scan-out buffers allocated through GBM (linear XRGB8888, mapped
// once). Each frame is scaled into the back buffer to fill the mode, keeping its aspect (black
// bars), and shown at the next vertical blank; the CRTC's previous configuration is restored at
// the end. EglDisplaySink shows a surround view drawn by OpenGL instead, with no copy.
//
// Error policy: the constructor throws RenderError naming the device and what is missing ("no
// connected connector (found: HDMI-A-1 disconnected, DP-1 disconnected)", "cannot become DRM
// master: another process drives the display"); consume() throws RenderError when a page flip
// fails, which ends this output.
// Threading: one thread at a time (behind a QueuedSink in the daemon).

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "render/outputs/frame_sink.hpp"
#include "render/outputs/kms_screen.hpp"

namespace surroundd::render {

class DrmDisplaySink final : public FrameSink {
 public:
  explicit DrmDisplaySink(const DrmDisplaySettings& settings);
  ~DrmDisplaySink() override;

  void consume(const cv::Mat& bgr, const PictureTime& time) override;
  void finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) override;
  // "display HDMI-A-1 1920x1080@60 on /dev/dri/card0 (123 frames)"
  std::string describe() const override;

 private:
  struct Buffers;  // the two scan-out buffers (keeps GBM out of the header)

  DrmCard card_;
  // The buffers go before the screen: a frame buffer keeps its buffer's memory until the screen,
  // having given the controller back, removes it.
  KmsScreen screen_;
  std::unique_ptr<Buffers> buffers_;
  std::uint64_t frames_ = 0;
};

}  // namespace surroundd::render
