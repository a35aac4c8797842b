#pragma once
// A surround view on a screen driven by the kernel (DRM/KMS), as OpenGL drew it: the view's
// framebuffer is blitted on the GPU into a GBM surface of the screen's mode (fitted, black bars
// around), swapped, and the surface's front buffer page-flipped onto the screen — kmscube's way;
// nothing is read back or copied by the CPU, which is what a vehicle's display needs.
// DrmDisplaySink is handed read-back pictures instead.
//
// The renderer's context must be on the GBM platform, on the card's GBM device
// (EglContext(EglPlatform::kGbm, card.gbm(), ...), DrmCard in kms_screen.hpp): a GBM surface and
// the EGL surface on it belong to that device, and only the card's master may flip its screen.
// The renderer's thread never waits for the screen: a view drawn while the last flip is still
// pending (faster than the screen's refresh) is not shown, the next one is.
//
// Error policy: the constructor throws RenderError (a context on another platform, no such
// connector, no GBM or EGL surface); present() throws RenderError when a swap or page flip
// fails, or a flip has not completed within 500 ms (the display is gone), which ends the output;
// consume() for any picture (it shows views only).
// Threading: every call on the thread that has the renderer's context.

#include <cstdint>
#include <memory>
#include <string>

#include "render/egl_context.hpp"
#include "render/outputs/frame_sink.hpp"
#include "render/outputs/kms_screen.hpp"

namespace surroundd::render {

class EglDisplaySink final : public FrameSink {
 public:
  // The screen of `connector` (empty: the first connected one) on the card that `gl`'s GBM
  // device is on; `gl` is current on this thread and outlives the sink.
  EglDisplaySink(EglContext& gl, const std::string& connector);
  ~EglDisplaySink() override;

  bool presentsViews() const override { return true; }
  // Shows `view`'s picture from the next vertical blank, unless the last flip is still pending.
  // Leaves the context drawing into framebuffer objects only (as before) and framebuffer 0 bound.
  void present(const SurroundView& view, const PictureTime& time) override;
  // Throws RenderError: it shows views drawn by OpenGL, not pictures.
  void consume(const cv::Mat& picture, const PictureTime& time) override;
  // Waits for the last flip: the screen then shows the last view presented.
  void finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) override;
  // "EGL display Virtual-1 1280x800@60 on /dev/dri/card0 (123 frames, 2 not shown: the screen
  // was still flipping)"
  std::string describe() const override;

  std::uint64_t framesShown() const { return framesShown_; }

 private:
  class Surface;  // the GBM surface, its EGL surface and the buffers locked for the screen

  EglContext& gl_;
  std::unique_ptr<Surface> surface_;
  // Destroyed before the surface: gives the display controller back and removes the frame
  // buffers while their buffers still exist.
  std::unique_ptr<KmsScreen> screen_;
  std::uint64_t framesShown_ = 0;
  std::uint64_t framesNotShown_ = 0;
};

}  // namespace surroundd::render
