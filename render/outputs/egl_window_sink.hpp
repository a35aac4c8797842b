#pragma once
// A window on an X server that shows a surround view through EGL: the view's picture goes from
// its framebuffer to the window on the GPU (a blit into the window surface's back buffer and a
// buffer swap that does not wait for the vertical blank), never read back to the CPU — which is
// what a display needs; X11WindowSink is handed a read-back picture instead.
//
// The renderer's context must be on the X11 platform, on the same server
// (EglContext(EglPlatform::kX11, ...)): EGL window surfaces belong to one EGL display, and a
// context draws only into its own display's. That ties the renderer to the server, but not its
// fate: the context draws into its framebuffer objects without the server (Mesa; tested on
// llvmpipe), so when the server goes away the other outputs' views go on and only the window
// stops, as X11WindowSink does. The window has a connection of its own for its events (X window
// ids are the server's, so the renderer's connection draws into it).
//
// Error policy: the constructor throws RenderError (a context on another platform, the display
// not opened, no visual for the context's configuration, no window surface, the window not shown
// within 5 s); present() throws RenderError for a view of another size and when the server
// reports an error, consume() for any picture (it shows views only). The user closing the window
// and the server going away are not errors: the sink stops wanting frames and describe() says why.
//
// Threading: every call on the thread that has the renderer's context.

#include <cstdint>
#include <memory>
#include <string>

#include "render/egl_context.hpp"
#include "render/outputs/frame_sink.hpp"
#include "render/outputs/x11_window_sink.hpp"

namespace surroundd::render {

class EglWindowSink final : public FrameSink {
 public:
  // A window of settings.size on settings.display, drawn into by `gl`, which is current on this
  // thread and outlives the sink.
  EglWindowSink(EglContext& gl, X11WindowSettings settings);
  ~EglWindowSink() override;

  bool presentsViews() const override { return true; }
  // Shows `view`'s picture (of the window's size) after handling the window's events; nothing
  // once it was closed or the display went away. Leaves the context drawing into framebuffer
  // objects only (as before) and framebuffer 0 bound.
  void present(const SurroundView& view, const PictureTime& time) override;
  // Throws RenderError: it shows views drawn by OpenGL, not pictures.
  void consume(const cv::Mat& picture, const PictureTime& time) override;
  // False once the window was closed or the display went away.
  bool wantsFrame(std::chrono::nanoseconds streamTime) const override;
  // The window keeps showing the last picture until the sink is destroyed.
  void finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) override;
  // "EGL window on :42 (123 frames)", plus why it stopped if it did.
  std::string describe() const override;

  // The window's X id; 0 once it is gone.
  unsigned long windowId() const;
  std::uint64_t framesShown() const { return framesShown_; }

 private:
  class Surface;  // the connection, the window and its EGL surface (keeps Xlib out of here)

  EglContext& gl_;
  X11WindowSettings settings_;
  // Reading the window's events (wantsFrame()) changes what it knows of the window.
  std::unique_ptr<Surface> surface_;
  std::uint64_t framesShown_ = 0;
};

}  // namespace surroundd::render
