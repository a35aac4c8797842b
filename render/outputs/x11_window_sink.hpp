#pragma once
// A live window on an X server: each frame is shown as it comes, at its own size (no scaling).
//
// Per frame: one BGR → BGRX conversion into a picture allocated once — memory shared with the
// server (MIT-SHM) when it offers that, else sent over the socket (XPutImage) — and one round trip,
// so that the frame is on screen, and the memory free again, when consume() returns. The window
// redraws its last frame when it is uncovered (Expose).
//
// Error policy: the constructor throws RenderError when the display cannot be opened ("X11 window:
// cannot open display ':42'"), has no 24-bit TrueColor visual, or does not map the window within
// 5 s; consume() throws RenderError for a frame that is not 8-bit BGR of `size`, and when the
// server reports an error. The user closing the window (WM_DELETE_WINDOW, or the window destroyed)
// and the server going away are not errors: the sink stops wanting frames and describe() says why.
// Xlib's default of exit(1) on X errors is replaced for this sink's connection (see
// xlib_display.hpp).
//
// Threading: consume() and finish() from one thread at a time (the pipeline's, or a QueuedSink's);
// wantsFrame() from any thread: it handles the window's pending events (close, expose) without
// blocking, so a window stays responsive between frames that are shown, and leaves that to
// consume() while one is being shown.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include <opencv2/core.hpp>

#include "render/outputs/frame_sink.hpp"

namespace surroundd::render {

struct X11WindowSettings {
  std::string display;              // X display name, e.g. ":0"; empty: $DISPLAY
  std::string title = "surroundd";  // window title, UTF-8
  cv::Size size;                    // window size in pixels; every frame must have it

  bool operator==(const X11WindowSettings&) const = default;
};

class X11WindowSink final : public FrameSink {
 public:
  explicit X11WindowSink(X11WindowSettings settings);
  ~X11WindowSink() override;

  void consume(const cv::Mat& bgr, const PictureTime& time) override;
  // False once the window was closed or the display went away.
  bool wantsFrame(std::chrono::nanoseconds streamTime) const override;
  // The window keeps showing the last frame until the sink is destroyed.
  void finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) override;
  // "window on :42 (123 frames)", plus why it stopped if it did.
  std::string describe() const override;

  // For tests and diagnostics: the window's X id (0 once it is gone), whether frames reach the
  // server through MIT-SHM, and how many frames were shown.
  unsigned long windowId() const;
  bool sharedMemory() const;
  std::uint64_t framesShown() const { return framesShown_; }

 private:
  class ShownWindow;  // the connection, the window and its picture (keeps Xlib out of this header)

  X11WindowSettings settings_;
  // Xlib's connection is used by one thread at a time: this guards window_ after construction.
  mutable std::mutex xlib_;
  std::unique_ptr<ShownWindow> window_;
  mutable std::atomic<bool> open_{true};  // the window's state when last looked at
  std::uint64_t framesShown_ = 0;
};

}  // namespace surroundd::render
