#pragma once
// A window on an X server that the renderer shows a surround view in through EGL: the view's
// picture goes from its framebuffer to the window on the GPU (a blit into the window surface's
// back buffer and a buffer swap that does not wait for the vertical blank), never read back to
// the CPU, which is what a display needs (X11WindowSink is handed a read-back picture instead).
//
// The renderer's context must be on the X11 platform, on this window's connection
// (EglContext(EglPlatform::kX11, display)): EGL window surfaces belong to one EGL display, and a
// context draws only into its own display's. That ties the renderer to the server, but not its
// fate: the context draws into its framebuffer objects without the server (Mesa; tested on
// llvmpipe), so when the server goes away the other outputs' views go on and only the window
// stops, as X11WindowSink does.
//
// Error policy: the constructor throws RenderError (a context on another platform, no visual for
// its configuration, no window surface, the window not shown within 5 s); present() throws
// RenderError for a view of another size and when the server reports an error. The user closing
// the window and the server going away are not errors: present() returns false from then on and
// describe() says why.
//
// Threading: on the thread that has the renderer's context, which is the one thread that uses the
// display's connection.

#include <cstdint>
#include <memory>
#include <string>

#include "render/egl_context.hpp"
#include "render/outputs/x11_window_sink.hpp"
#include "render/surround_view.hpp"

namespace surroundd::render {

class XlibDisplay;

class EglWindow {
 public:
  // A window of settings.size on `display` (which must outlive it; settings.display is not
  // used), drawn into by `gl`, which is current on this thread and outlives the window.
  EglWindow(EglContext& gl, XlibDisplay& display, const X11WindowSettings& settings);
  ~EglWindow();
  EglWindow(const EglWindow&) = delete;
  EglWindow& operator=(const EglWindow&) = delete;

  // Shows `view`'s last drawn picture, after handling the window's events; false, and nothing
  // shown, once the window was closed or the display went away. Leaves the context drawing into
  // framebuffer objects only (as before), framebuffer 0 bound.
  bool present(const SurroundView& view);

  bool open() const;
  // The window's X id; 0 once it is gone.
  unsigned long windowId() const;
  std::uint64_t framesShown() const { return framesShown_; }
  // "EGL window on :42 (123 frames)", plus why it stopped if it did.
  std::string describe() const;

 private:
  class Surface;  // the window and its EGL surface (keeps Xlib out of this header)

  EglContext& gl_;
  cv::Size size_;
  std::unique_ptr<Surface> surface_;
  std::uint64_t framesShown_ = 0;
};

}  // namespace surroundd::render
