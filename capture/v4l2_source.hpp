#pragma once
// A live camera through V4L2 (video4linux2): opened by a stable path (/dev/v4l/by-path/...,
// /dev/v4l/by-id/...) or /dev/videoN, the pixel format, size and frame rate negotiated from the
// settings, MMAP streaming, frames copied out of the driver's buffers as they are (YUYV, UYVY,
// NV12) or converted to BGR once (BGR; MJPEG through libjpeg-turbo: capture/pixel_conversion.hpp),
// with the driver's monotonic timestamps. Single-planar devices (UVC) and
// multi-planar ones (V4L2_CAP_VIDEO_CAPTURE_MPLANE: i.MX, Rockchip, TI capture drivers) alike;
// through the multi-planar API, NV12 also comes as NV12M (luma and chroma in two buffers).
//
// Faults at run time are read() statuses: a corrupt frame is kFault; no frame within the timeout
// or the device gone (ENODEV, EIO) closes it and is kLost, and reopen() opens and starts it again
// (when and how often is the recovery policy's choice, capture/source_recovery.hpp).
//
// Asked to (lendBuffers), it lends its frames the driver's buffers instead of copying them, where
// a frame's picture can view one as it is: for a GPU that imports the buffers' DMABUFs (render/
// camera_texture.hpp), so that no byte of a frame is copied on the way.

#include <array>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "capture/frame_source.hpp"
#include "capture/jpeg_decoder.hpp"
#include "capture/pixel_conversion.hpp"
#include "capture/v4l2_buffers.hpp"
#include "capture/v4l2_device.hpp"

struct v4l2_buffer;

namespace surroundd::capture {

enum class V4l2Format { kAuto, kYuyv, kUyvy, kNv12, kMjpeg };
const char* toString(V4l2Format format);
struct V4l2FormatCode;

// A V4L2 control by its name in the config: exposure_auto, exposure_absolute, gain,
// white_balance_auto, white_balance_temperature, brightness, contrast, saturation.
struct V4l2Control {
  std::string name;
  std::int32_t value = 0;
  bool operator==(const V4l2Control&) const = default;
};

struct V4l2Settings {
  std::filesystem::path device;
  cv::Size size{1280, 720};
  double fps = 30;
  V4l2Format format = V4l2Format::kAuto;   // auto: YUYV, UYVY, NV12, MJPEG, the first offered
  int buffers = 4;                         // driver buffers, 2..32
  std::chrono::milliseconds timeout{500};  // no frame for this long: the camera is lost
  std::vector<V4l2Control> controls;
  bool operator==(const V4l2Settings&) const = default;
};

class V4l2Source final : public FrameSource {
 public:
  // Opens and starts the device. Throws CaptureError naming the camera and device: it cannot be
  // opened, cannot stream, does not offer the format and size (the message lists what it offers),
  // or refuses a control.
  V4l2Source(std::string cameraName, V4l2Settings settings,
             std::unique_ptr<V4l2Device> device = makeKernelV4l2Device());
  ~V4l2Source() override;

  cv::Size frameSize() const override { return settings_.size; }
  // YUYV, UYVY and NV12 as the camera gives them, the other formats converted to BGR.
  PixelFormat pixelFormat() const override { return heldFormat(layout_); }
  Timestamp nominalPeriod() const override { return period_; }
  ReadStatus read(Frame& out) override;
  const std::string& lastError() const override { return error_; }
  void reopen() override;

  V4l2Format format() const { return format_; }  // as negotiated
  std::uint64_t reopened() const { return reopened_; }
  bool multiplanar() const { return multiplanar_; }  // through the multi-planar API
  // The driver buffers as DMABUF file descriptors, where the driver exports them (VIDIOC_EXPBUF),
  // for importing frames into a GPU without a copy; empty where it does not. One per plane, buffer
  // after buffer.
  std::span<const int> dmabufs() const { return dmabufs_; }

  // Where it can (lendingRefusal()), a frame is from now on the driver's buffer lent to it rather
  // than a copy: its image views the buffer, its dmabuf says where the buffer's planes are, and
  // the buffer goes back to the driver when the frame returns to its pool. With fewer than two
  // other buffers left to the driver, frames are copied as before (V4l2Settings::buffers: enough
  // for every frame the pipeline holds at once, and two more).
  const char* lendBuffers() override;
  // Why this source's frames cannot be lent its buffers (as negotiated); nullptr when they can.
  const char* lendingRefusal() const;

 private:
  void start();  // open, negotiate, map, stream; throws CaptureError
  void setFormat(const V4l2FormatCode& chosen, const std::function<CaptureError()>& cannot);
  void mapBuffers();
  void stop();  // stream off, unmap, close; never throws
  ReadStatus fault(std::string message, bool lost);
  // Each plane's bytes, as the driver filled them; false (and error_ set) when they cannot be.
  bool filled(const v4l2_buffer& buffer, std::array<std::span<const std::uint8_t>, 2>& data);
  bool hold(const v4l2_buffer& buffer, cv::Mat& held);
  bool lend(const v4l2_buffer& buffer, Frame& out);
  std::string where() const;

  std::string camera_;
  V4l2Settings settings_;
  std::shared_ptr<V4l2Device> device_;  // shared with the buffers, which frames may hold longer
  JpegDecoder jpeg_;
  V4l2Format format_ = V4l2Format::kAuto;
  PixelLayout layout_ = PixelLayout::kYuyv;
  bool multiplanar_ = false;
  std::uint32_t bufferType_ = 0;           // V4L2_BUF_TYPE_VIDEO_CAPTURE or ..._MPLANE
  std::vector<std::size_t> bytesPerLine_;  // per plane
  Timestamp period_{0};
  std::shared_ptr<V4l2Buffers> buffers_;  // this streaming session's
  std::vector<int> dmabufs_;              // buffers_'s exports, in order
  bool requested_ = false;  // buffers were requested (VIDIOC_REQBUFS) and must be released
  bool orphans_ = false;    // V4L2_BUF_CAP_SUPPORTS_ORPHANED_BUFS: buffers may outlive their stream
  bool lend_ = false;       // set before the source is read (FrameSource::lendBuffers)
  bool streaming_ = false;
  std::uint64_t reopened_ = 0;
  std::string error_;
};

}  // namespace surroundd::capture
