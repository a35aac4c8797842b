#pragma once
// One rendered output of the surround scene: a framebuffer of the output's size, the view shown
// in it (switchable at any time), and an asynchronous read-back through a pixel buffer object.
//
// Per frame: draw() renders and starts the read-back (on a renderer that runs on the CPU: starts
// the rasterization); the caller does other work (the next frame's stitch) while the GPU
// finishes, or collects as soon as finished() says it would not wait; collect() waits for the
// pixels. Nothing is allocated per frame.

#include <chrono>
#include <optional>

#include <opencv2/core.hpp>

#include "render/gl_objects.hpp"
#include "render/gpu_timer.hpp"
#include "render/surround_scene.hpp"
#include "render/view_camera.hpp"

namespace surroundd::render {

// When a view's picture was drawn, and whether it shows its view settled (no switch under way):
// what the time from a switch's request to the new view on screen is measured by.
struct DrawnPicture {
  std::chrono::steady_clock::time_point at;
  bool settled = true;
};

class SurroundView {
 public:
  // `size`: even width and height. The scene must outlive the view, and `timer` (may be null)
  // too: it times the draws and read-backs on the GPU.
  SurroundView(const SurroundScene& scene, cv::Size size, ViewKind view, ViewSettings settings,
               GpuTimer* timer = nullptr);

  // Shows `view` from the next draw() on: moving there over settings.transitionS of stream time
  // (the eye's pose in between for top and orbit; the two pictures faded for the others), or at
  // once with transitionS 0.
  void setView(ViewKind view);
  ViewKind view() const { return view_; }
  cv::Size size() const { return size_; }
  // Whether its picture changes with stream time for the same panorama: the orbiting eye of the
  // orbit and split views (ViewSettings::orbitPeriodS), and a switch of view under way.
  bool moves() const { return transitioning_ || !settlesStill(); }
  // Whether the view it shows (or is switching to) stands still once there: all but the orbiting
  // eye.
  bool settlesStill() const;
  // Where the split view shows its camera's own picture, letterboxed in the right half; none for
  // the other views.
  std::optional<cv::Rect> cameraArea() const;

  // Renders the scene as it was last uploaded; `timeS` moves the orbiting eye. With kNo the
  // picture stays in framebuffer() for what shows it on the GPU, and nothing is pending.
  enum class ReadBack { kYes, kNo };
  void draw(double timeS, ReadBack readBack = ReadBack::kYes);
  bool pending() const { return pending_; }
  // Whether the pending picture can be collected without waiting: drawn (and on a GPU, copied).
  bool finished() const { return pending_ && drawnFence_.passed(); }
  // The last draw(): when, and whether the switch of view had ended by then.
  DrawnPicture drawn() const { return drawn_; }
  // The picture of the last draw(), 8-bit BGR; valid until the next collect().
  const cv::Mat& collect();
  // The framebuffer the view draws into: row 0 of its colour is the picture's top row (as the
  // read-back gives it), for what shows it on the GPU without reading it back (EglWindow).
  GLuint framebuffer() const { return framebuffer_.name(); }

  // Where each pixel of the view (as it is now, its eye at `timeS`) samples the panorama, in
  // panorama pixels (centres at integers, as PanoramaGeometry): CV_32FC2, NaN where it shows no
  // panorama (the car, the background, the split view's camera half). Rendered with the same
  // geometry and interpolation as draw(), to 1/65536 of the panorama's width and 1/32767 of its
  // height (1/32 of a pixel of a 2048 x 1024 panorama). For setting up a view that does not
  // move; it allocates, and waits for the GPU.
  cv::Mat panoramaPositions(double timeS) const;
  // The scene's guidelines alone as this view shows them now (black elsewhere; none in the 360
  // view), 8-bit BGR, read back at once: for a view whose picture is gathered rather than drawn.
  // Valid until the next call; allocates the first time only.
  const cv::Mat& guidelineLayer(double timeS);
  // Where such positions show the panorama: CV_8U, 255 there, 0 elsewhere.
  static cv::Mat panoramaShown(const cv::Mat& panoramaPositions);
  // The view's picture as it shows once settled (the switch under way, if any, ended), 8-bit BGR,
  // drawn into a target of its own: the pending picture stays. For the car and background of a
  // view that does not move; it allocates, and waits for the GPU.
  cv::Mat stillPicture(double timeS) const;

 private:
  void drawScene(ViewKind view, double timeS, SurroundScene::Pass pass) const;
  // `pass` of the view as it shows settled, drawn into an 8-bit RGBA target of its own and read
  // back at once.
  cv::Mat drawAlone(SurroundScene::Pass pass, double timeS) const;
  // The picture into this view's framebuffer (bound), the switch of view blended in.
  void drawPicture(double timeS);
  // glReadPixels of this view's framebuffer (bound) into readBuffer_.
  void startReadBack();
  // How far the switch of view has come at `timeS`, 0..1; 1 when none is under way (and it ends
  // there). Its start is the first draw after setView().
  double transitionProgress(double timeS);

  const SurroundScene& scene_;
  cv::Size size_;
  ViewKind view_;
  ViewSettings settings_;
  GpuTimer* timer_;
  gl::Framebuffer framebuffer_;
  gl::Renderbuffer colour_;
  gl::Renderbuffer depth_;
  gl::Buffer readBuffer_;
  // Where the read-back starts. A GPU copies into the pixel buffer on its own, so the copy is
  // queued right after the draw. A renderer on the CPU (llvmpipe) rasterizes on its own threads
  // once flushed, but its glReadPixels into a buffer waits for all of it (12-20 ms at 1280x720,
  // measured here): there the draw is only flushed, rasterized while the next set is stitched,
  // and read in collect().
  bool readAtCollect_;
  gl::Fence drawnFence_;      // after the last draw (and its read-back, where it starts there)
  bool pending_ = false;      // drawn, not collected
  bool readStarted_ = false;  // the pending picture is on its way into readBuffer_
  ViewKind from_;             // the view a switch under way started from
  bool transitioning_ = false;
  std::optional<double> transitionStartS_;
  DrawnPicture drawn_;
  cv::Mat picture_;
  cv::Mat guidelineRgba_;  // guidelineLayer()'s read-back, and its picture
  cv::Mat guidelineLayer_;
};

}  // namespace surroundd::render
