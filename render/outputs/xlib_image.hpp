#pragma once
// Internal to render/: a picture in the X server's 32-bit TrueColor layout (bytes B, G, R, X),
// allocated once and drawn into a window as often as wanted. Its memory is a System V shared memory
// segment that the server reads directly (MIT-SHM) when the server offers the extension and can
// attach the segment (a local server); otherwise it is ours and each put() sends it over the
// socket.
//
// Error policy: the constructor throws RenderError when the visual is not 24-bit TrueColor with
// 8 bits per channel; X errors of put() surface at the caller's next XlibDisplay::sync().

#include <cstdint>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "render/outputs/xlib_display.hpp"

namespace surroundd::render {

// One System V shared memory segment, attached to this process while it lives.
class SharedMemorySegment {
 public:
  // Returns null when the system refuses (no SysV IPC, limits).
  static std::unique_ptr<SharedMemorySegment> create(std::size_t bytes);
  ~SharedMemorySegment();
  SharedMemorySegment(const SharedMemorySegment&) = delete;
  SharedMemorySegment& operator=(const SharedMemorySegment&) = delete;

  int id() const { return id_; }
  char* address() const { return address_; }
  // Marks the segment for removal once every process detached, so that it cannot outlive us even
  // if we crash. Call once the X server has attached it.
  void removeWhenDetached();

 private:
  SharedMemorySegment(int id, char* address) : id_(id), address_(address) {}
  int id_;
  char* address_;
  bool removed_ = false;
};

class XlibImage {
 public:
  XlibImage(XlibDisplay& display, const XVisualInfo& visual, cv::Size size);
  ~XlibImage();
  XlibImage(const XlibImage&) = delete;
  XlibImage& operator=(const XlibImage&) = delete;

  // The pixels: a CV_8UC4 (B, G, R, X) header over the image's own memory. Const, so that OpenCV
  // writes into it and throws rather than allocating a new buffer when given another size or type.
  const cv::Mat& pixels() { return pixels_; }
  // Queues drawing the whole picture at (0, 0) of `drawable`. The memory must not change until the
  // server has done it: XlibDisplay::sync() waits for that.
  void put(Drawable drawable, GC gc);
  bool sharedMemory() const { return attached_; }

 private:
  struct ImageDeleter {
    void operator()(XImage* image) const;
  };

  // Tries MIT-SHM; leaves everything empty when the server has no MIT-SHM or refuses the segment.
  void trySharedMemory(const XVisualInfo& visual, cv::Size size);

  XlibDisplay* display_;
  std::unique_ptr<SharedMemorySegment> segment_;  // with MIT-SHM
  std::vector<std::uint8_t> memory_;              // without
  XShmSegmentInfo shmInfo_{};
  bool attached_ = false;                        // the server attached segment_
  std::unique_ptr<XImage, ImageDeleter> image_;  // its data points into segment_ or memory_
  cv::Mat pixels_;
};

}  // namespace surroundd::render
