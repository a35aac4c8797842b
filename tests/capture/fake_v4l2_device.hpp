#pragma once
// An in-process V4L2 device for tests: it answers the ioctls the V4L2 source makes the way a
// driver does (formats and sizes to enumerate, MMAP buffers, a queue), through the single-planar
// API (UVC) or only the multi-planar one (i.MX, Rockchip, TI: V4L2_CAP_VIDEO_CAPTURE_MPLANE, with
// NV12M's luma and chroma in two buffers and lines padded to the driver's stride, refusing the
// other API's buffer type), produces frames of a
// synthetic picture in the negotiated format with monotonic timestamps, and fails on request:
// unplugged (ENODEV, then open fails until plugged back), stalled (poll times out without
// waiting), corrupt MJPEG. A fault can also be scheduled before streaming starts (corruptFrames,
// unplugAtFrame), so that a test can leave the device to a capture thread without touching it.
//
// The test keeps a FakeV4l2Device::State to steer the device after handing the device to a
// source. Like a driver, the device may be called from several threads at once (a frame lent a
// buffer gives it back on the thread that lets it go): every call is under one lock.

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <deque>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <vector>

#include <fcntl.h>
#include <linux/videodev2.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/v4l2_device.hpp"

namespace surroundd::testing {

// BGR to packed 4:2:2 (YUYV or UYVY), BT.601 limited range like OpenCV's conversion back.
inline std::vector<std::uint8_t> packedYuv(const cv::Mat& bgr, bool yuyv) {
  cv::Mat yuv;
  cv::cvtColor(bgr, yuv, cv::COLOR_BGR2YCrCb);  // full-range; adjust to limited below
  std::vector<std::uint8_t> out(static_cast<std::size_t>(bgr.total()) * 2);
  const auto limitedY = [](int y) { return static_cast<std::uint8_t>(16 + y * 219 / 255); };
  const auto limitedC = [](int c) {
    return static_cast<std::uint8_t>(128 + (c - 128) * 224 / 255);
  };
  for (int r = 0; r < bgr.rows; ++r) {
    for (int c = 0; c < bgr.cols; c += 2) {
      const auto a = yuv.at<cv::Vec3b>(r, c);
      const auto b = yuv.at<cv::Vec3b>(r, c + 1);
      const std::uint8_t y0 = limitedY(a[0]), y1 = limitedY(b[0]);
      const std::uint8_t cr = limitedC((a[1] + b[1]) / 2), cb = limitedC((a[2] + b[2]) / 2);
      std::uint8_t* p = out.data() + (static_cast<std::size_t>(r) * bgr.cols + c) * 2;
      if (yuyv) {
        p[0] = y0, p[1] = cb, p[2] = y1, p[3] = cr;
      } else {
        p[0] = cb, p[1] = y0, p[2] = cr, p[3] = y1;
      }
    }
  }
  return out;
}

inline std::string fourccName(std::uint32_t fourcc) {
  std::string name(4, ' ');
  for (std::size_t i = 0; i < 4; ++i) name[i] = static_cast<char>((fourcc >> (8 * i)) & 0xff);
  return name;
}

inline std::vector<std::uint8_t> nv12(const cv::Mat& bgr) {
  cv::Mat i420;
  cv::cvtColor(bgr, i420, cv::COLOR_BGR2YUV_I420);
  const std::size_t luma = bgr.total();
  const std::size_t chroma = luma / 4;
  std::vector<std::uint8_t> out(luma + 2 * chroma);
  std::memcpy(out.data(), i420.data, luma);
  for (std::size_t i = 0; i < chroma; ++i) {
    out[luma + 2 * i] = i420.data[luma + i];               // U
    out[luma + 2 * i + 1] = i420.data[luma + chroma + i];  // V
  }
  return out;
}

class FakeV4l2Device final : public surroundd::capture::V4l2Device {
 public:
  struct Mode {
    std::uint32_t fourcc;
    cv::Size size;
  };
  struct State {
    std::vector<Mode> modes;
    std::vector<v4l2_queryctrl> controls;
    std::vector<v4l2_control> controlsSet;
    bool multiplanar = false;       // only the multi-planar API
    std::uint32_t linePadding = 0;  // bytes after each line of a raw format, multi-planar only
    bool plugged = true;
    int stalledPolls = 0;      // the next polls time out
    bool corruptNext = false;  // the next MJPEG frame is cut short
    int corruptFrames = 0;     // the next this many MJPEG frames are cut short
    // Once this many frames are produced the device is unplugged; the next `failedOpens` opens
    // fail, and the one after plugs it back.
    std::uint64_t unplugAtFrame = std::numeric_limits<std::uint64_t>::max();
    int failedOpens = 0;
    bool exportsDmabuf = false;         // VIDIOC_EXPBUF answers (with /dev/null descriptors)
    int failedExports = 0;              // the next this many VIDIOC_EXPBUF calls fail (EMFILE)
    std::uint32_t grantedBuffers = 32;  // VIDIOC_REQBUFS grants at most this many
    bool orphanedBuffers = true;        // V4L2_BUF_CAP_SUPPORTS_ORPHANED_BUFS
    int opens = 0;
    std::uint64_t produced = 0;
    std::uint64_t queued = 0;  // VIDIOC_QBUF calls
    std::int64_t firstTimestampUs = 1'000'000;
    std::int64_t periodUs = 33'333;
    std::function<cv::Mat(std::uint64_t frame, cv::Size size)> picture;
  };

  explicit FakeV4l2Device(std::shared_ptr<State> state) : state_(std::move(state)) {}

  int open(const std::string&) override {
    const std::lock_guard lock(mutex_);
    if (!state_->plugged && state_->failedOpens > 0) {
      --state_->failedOpens;
      if (state_->failedOpens == 0 && state_->unplugAtFrame == state_->produced) {
        state_->plugged = true;  // the scheduled unplugging is over after this failed open
        state_->unplugAtFrame = std::numeric_limits<std::uint64_t>::max();
      }
      return ENOENT;
    }
    if (!state_->plugged) return ENOENT;
    ++state_->opens;
    open_ = true;
    return 0;
  }
  void close() override {
    const std::lock_guard lock(mutex_);
    open_ = false;
    streaming_ = false;
    retire();
    queue_.clear();
  }
  void* map(std::size_t length, std::int64_t offset) override {
    const std::lock_guard lock(mutex_);
    const auto index = static_cast<std::size_t>(offset >> 16);
    const auto plane = static_cast<std::size_t>((offset >> 12) & 0xf);
    if (index >= buffers_.size() || plane >= buffers_[index].size() ||
        buffers_[index][plane].size() != length) {
      return nullptr;
    }
    return buffers_[index][plane].data();
  }
  void unmap(void*, std::size_t) override {}
  int waitReadable(std::chrono::milliseconds) override {
    const std::lock_guard lock(mutex_);
    if (!state_->plugged) return ENODEV;
    if (state_->stalledPolls > 0) {
      --state_->stalledPolls;
      return ETIMEDOUT;
    }
    return streaming_ && !queue_.empty() ? 0 : ETIMEDOUT;
  }

  int ioctl(unsigned long request, void* argument) override {
    const std::lock_guard lock(mutex_);
    if (!open_) return EBADF;
    if (!state_->plugged) return ENODEV;
    const std::uint32_t type =
        state_->multiplanar ? V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE : V4L2_BUF_TYPE_VIDEO_CAPTURE;
    switch (request) {
      case VIDIOC_QUERYCAP: {
        auto* caps = static_cast<v4l2_capability*>(argument);
        *caps = {};
        std::strcpy(reinterpret_cast<char*>(caps->driver), "fake");
        std::strcpy(reinterpret_cast<char*>(caps->card), "Fake camera");
        caps->capabilities =
            V4L2_CAP_STREAMING |
            (state_->multiplanar ? V4L2_CAP_VIDEO_CAPTURE_MPLANE : V4L2_CAP_VIDEO_CAPTURE);
        return 0;
      }
      case VIDIOC_ENUM_FMT: {
        auto* description = static_cast<v4l2_fmtdesc*>(argument);
        if (description->type != type) return EINVAL;
        const auto fourccs = distinctFourccs();
        if (description->index >= fourccs.size()) return EINVAL;
        description->pixelformat = fourccs[description->index];
        return 0;
      }
      case VIDIOC_ENUM_FRAMESIZES: {
        auto* size = static_cast<v4l2_frmsizeenum*>(argument);
        std::uint32_t k = 0;
        for (const auto& mode : state_->modes) {
          if (mode.fourcc != size->pixel_format) continue;
          if (k++ == size->index) {
            size->type = V4L2_FRMSIZE_TYPE_DISCRETE;
            size->discrete = {static_cast<std::uint32_t>(mode.size.width),
                              static_cast<std::uint32_t>(mode.size.height)};
            return 0;
          }
        }
        return EINVAL;
      }
      case VIDIOC_ENUM_FRAMEINTERVALS: {
        auto* interval = static_cast<v4l2_frmivalenum*>(argument);
        const bool offered = std::ranges::any_of(state_->modes, [&](const Mode& mode) {
          return mode.fourcc == interval->pixel_format &&
                 mode.size == cv::Size(static_cast<int>(interval->width),
                                       static_cast<int>(interval->height));
        });
        if (!offered || interval->index != 0) return EINVAL;
        interval->type = V4L2_FRMIVAL_TYPE_DISCRETE;
        interval->discrete = {static_cast<std::uint32_t>(state_->periodUs), 1'000'000};
        return 0;
      }
      case VIDIOC_S_FMT:
        return setFormat(*static_cast<v4l2_format*>(argument), type);
      case VIDIOC_G_PARM:
      case VIDIOC_S_PARM: {
        auto* parameters = static_cast<v4l2_streamparm*>(argument);
        if (parameters->type != type) return EINVAL;
        parameters->parm.capture.capability = V4L2_CAP_TIMEPERFRAME;
        parameters->parm.capture.timeperframe = {1, 30};
        return 0;
      }
      case VIDIOC_QUERYCTRL: {
        auto* query = static_cast<v4l2_queryctrl*>(argument);
        for (const auto& control : state_->controls) {
          if (control.id == query->id) {
            *query = control;
            return 0;
          }
        }
        return EINVAL;
      }
      case VIDIOC_S_CTRL:
        state_->controlsSet.push_back(*static_cast<v4l2_control*>(argument));
        return 0;
      case VIDIOC_REQBUFS: {
        auto* wanted = static_cast<v4l2_requestbuffers*>(argument);
        if (wanted->type != type) return EINVAL;
        retire();
        wanted->count = std::min(wanted->count, state_->grantedBuffers);
        wanted->capabilities = V4L2_BUF_CAP_SUPPORTS_MMAP |
                               (state_->orphanedBuffers ? V4L2_BUF_CAP_SUPPORTS_ORPHANED_BUFS : 0);
        buffers_.assign(wanted->count, {});
        for (auto& planes : buffers_) {
          for (std::uint32_t p = 0; p < planeCount(); ++p) planes.emplace_back(planeBytes(p));
        }
        queue_.clear();
        return 0;
      }
      case VIDIOC_QUERYBUF: {
        auto* buffer = static_cast<v4l2_buffer*>(argument);
        if (buffer->type != type || buffer->index >= buffers_.size()) return EINVAL;
        const auto& planes = buffers_[buffer->index];
        if (!state_->multiplanar) {
          buffer->length = static_cast<std::uint32_t>(planes[0].size());
          buffer->m.offset = buffer->index << 16;
          return 0;
        }
        if (buffer->m.planes == nullptr || buffer->length < planes.size()) return EINVAL;
        buffer->length = static_cast<std::uint32_t>(planes.size());
        for (std::uint32_t p = 0; p < planes.size(); ++p) {
          buffer->m.planes[p].length = static_cast<std::uint32_t>(planes[p].size());
          buffer->m.planes[p].m.mem_offset = (buffer->index << 16) | (p << 12);
        }
        return 0;
      }
      case VIDIOC_EXPBUF: {
        if (!state_->exportsDmabuf) return ENOTTY;
        if (state_->failedExports > 0) {
          --state_->failedExports;
          return EMFILE;
        }
        auto* exported = static_cast<v4l2_exportbuffer*>(argument);
        if (exported->type != type || exported->plane >= planeCount()) return EINVAL;
        exported->fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
        return 0;
      }
      case VIDIOC_QBUF: {
        const auto* buffer = static_cast<v4l2_buffer*>(argument);
        if (buffer->type != type) return EINVAL;
        if (state_->multiplanar && (buffer->m.planes == nullptr || buffer->length < planeCount())) {
          return EINVAL;
        }
        // Like videobuf2: a buffer that is not there, or queued already, is refused.
        if (buffer->index >= buffers_.size() ||
            std::ranges::find(queue_, buffer->index) != queue_.end()) {
          return EINVAL;
        }
        queue_.push_back(buffer->index);
        ++state_->queued;
        return 0;
      }
      case VIDIOC_DQBUF: {
        auto* buffer = static_cast<v4l2_buffer*>(argument);
        if (buffer->type != type) return EINVAL;
        if (state_->multiplanar && (buffer->m.planes == nullptr || buffer->length < planeCount())) {
          return EINVAL;
        }
        return dequeue(*buffer);
      }
      case VIDIOC_STREAMON:
      case VIDIOC_STREAMOFF:
        if (*static_cast<int*>(argument) != static_cast<int>(type)) return EINVAL;
        streaming_ = request == VIDIOC_STREAMON;
        if (!streaming_) queue_.clear();
        return 0;
      default:
        return ENOTTY;
    }
  }

 private:
  // Like the kernel, which keeps a mapped buffer until it is unmapped: buffers released (closed,
  // requested anew) stay where they are for the device's life.
  void retire() {
    for (auto& planes : buffers_) retired_.push_back(std::move(planes));
    buffers_.clear();
  }

  std::vector<std::uint32_t> distinctFourccs() const {
    std::vector<std::uint32_t> fourccs;
    for (const auto& mode : state_->modes) {
      if (std::ranges::find(fourccs, mode.fourcc) == fourccs.end()) fourccs.push_back(mode.fourcc);
    }
    return fourccs;
  }

  int setFormat(v4l2_format& format, std::uint32_t type) {
    if (format.type != type) return EINVAL;
    const bool multi = state_->multiplanar;
    const std::uint32_t fourcc = multi ? format.fmt.pix_mp.pixelformat : format.fmt.pix.pixelformat;
    const cv::Size size = multi ? cv::Size(static_cast<int>(format.fmt.pix_mp.width),
                                           static_cast<int>(format.fmt.pix_mp.height))
                                : cv::Size(static_cast<int>(format.fmt.pix.width),
                                           static_cast<int>(format.fmt.pix.height));
    // Like a driver: an unsupported request is adjusted to the first mode, not refused.
    Mode mode = state_->modes.front();
    for (const auto& m : state_->modes) {
      if (m.fourcc == fourcc && m.size == size) mode = m;
    }
    mode_ = mode;
    const auto width = static_cast<std::uint32_t>(mode.size.width);
    const auto height = static_cast<std::uint32_t>(mode.size.height);
    if (!multi) {
      auto& pix = format.fmt.pix;
      pix.pixelformat = mode.fourcc;
      pix.width = width;
      pix.height = height;
      pix.bytesperline = bytesPerLine(0);
      pix.sizeimage = planeBytes(0);
      return 0;
    }
    auto& pix = format.fmt.pix_mp;
    pix.pixelformat = mode.fourcc;
    pix.width = width;
    pix.height = height;
    pix.num_planes = static_cast<std::uint8_t>(planeCount());
    for (std::uint32_t p = 0; p < planeCount(); ++p) {
      pix.plane_fmt[p].bytesperline = bytesPerLine(p);
      pix.plane_fmt[p].sizeimage = planeBytes(p);
    }
    return 0;
  }

  bool mjpeg() const { return mode_.fourcc == V4L2_PIX_FMT_MJPEG; }
  std::uint32_t planeCount() const { return mode_.fourcc == V4L2_PIX_FMT_NV12M ? 2 : 1; }
  std::uint32_t padding() const {
    return state_->multiplanar && !mjpeg() ? state_->linePadding : 0;
  }
  std::uint32_t bytesPerLine(std::uint32_t /*plane*/) const {
    const auto width = static_cast<std::uint32_t>(mode_.size.width);
    const bool packed = mode_.fourcc == V4L2_PIX_FMT_YUYV || mode_.fourcc == V4L2_PIX_FMT_UYVY;
    return (packed ? width * 2 : width) + padding();
  }
  std::uint32_t planeRows(std::uint32_t plane) const {
    const auto height = static_cast<std::uint32_t>(mode_.size.height);
    if (mode_.fourcc == V4L2_PIX_FMT_NV12) return height * 3 / 2;
    if (mode_.fourcc == V4L2_PIX_FMT_NV12M) return plane == 0 ? height : height / 2;
    return height;
  }
  std::uint32_t planeBytes(std::uint32_t plane) const {
    if (mjpeg()) return static_cast<std::uint32_t>(mode_.size.area()) * 3;  // room for any JPEG
    return bytesPerLine(plane) * planeRows(plane);
  }

  // `bytes` (rows of `width` bytes, back to back) laid out with the driver's stride.
  std::vector<std::uint8_t> strided(const std::vector<std::uint8_t>& bytes, std::uint32_t width,
                                    std::uint32_t rows) const {
    if (padding() == 0) return bytes;
    std::vector<std::uint8_t> out(static_cast<std::size_t>(width + padding()) * rows, 0xAA);
    for (std::uint32_t r = 0; r < rows; ++r) {
      std::memcpy(out.data() + static_cast<std::size_t>(r) * (width + padding()),
                  bytes.data() + static_cast<std::size_t>(r) * width, width);
    }
    return out;
  }

  // The frame's bytes, plane by plane.
  std::vector<std::vector<std::uint8_t>> frameBytes(const cv::Mat& picture) {
    const auto width = static_cast<std::uint32_t>(picture.cols);
    const auto height = static_cast<std::uint32_t>(picture.rows);
    if (mode_.fourcc == V4L2_PIX_FMT_YUYV || mode_.fourcc == V4L2_PIX_FMT_UYVY) {
      return {strided(packedYuv(picture, mode_.fourcc == V4L2_PIX_FMT_YUYV), width * 2, height)};
    }
    if (mode_.fourcc == V4L2_PIX_FMT_NV12) return {strided(nv12(picture), width, height * 3 / 2)};
    if (mode_.fourcc == V4L2_PIX_FMT_NV12M) {
      const std::vector<std::uint8_t> both = nv12(picture);
      const std::size_t luma = static_cast<std::size_t>(width) * height;
      return {
          strided({both.begin(), both.begin() + static_cast<std::ptrdiff_t>(luma)}, width, height),
          strided({both.begin() + static_cast<std::ptrdiff_t>(luma), both.end()}, width,
                  height / 2)};
    }
    std::vector<std::uint8_t> bytes;
    cv::imencode(".jpg", picture, bytes, {cv::IMWRITE_JPEG_QUALITY, 95});
    if (state_->corruptNext || state_->corruptFrames > 0) {
      bytes.resize(bytes.size() / 3);  // a frame cut short on the wire
      state_->corruptNext = false;
      state_->corruptFrames = std::max(state_->corruptFrames - 1, 0);
    }
    return {bytes};
  }

  int dequeue(v4l2_buffer& buffer) {
    if (!streaming_ || queue_.empty()) return EAGAIN;
    if (state_->produced == state_->unplugAtFrame) {
      state_->plugged = false;
      return ENODEV;
    }
    const std::uint32_t index = queue_.front();
    queue_.pop_front();
    const std::uint64_t frame = state_->produced++;
    const auto planes = frameBytes(state_->picture(frame, mode_.size));
    for (std::size_t p = 0; p < planes.size(); ++p) {
      std::memcpy(buffers_[index][p].data(), planes[p].data(), planes[p].size());
    }
    v4l2_plane* planeInfo = buffer.m.planes;
    const std::uint32_t length = buffer.length;
    const std::uint32_t type = buffer.type;
    buffer = {};
    buffer.type = type;
    buffer.index = index;
    buffer.flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
    if (state_->multiplanar) {
      buffer.m.planes = planeInfo;
      buffer.length = length;
      for (std::size_t p = 0; p < planes.size(); ++p) {
        planeInfo[p] = {};
        planeInfo[p].bytesused = static_cast<std::uint32_t>(planes[p].size());
        planeInfo[p].length = static_cast<std::uint32_t>(buffers_[index][p].size());
      }
    } else {
      buffer.bytesused = static_cast<std::uint32_t>(planes[0].size());
    }
    const std::int64_t us =
        state_->firstTimestampUs + static_cast<std::int64_t>(frame) * state_->periodUs;
    buffer.timestamp = {us / 1'000'000, us % 1'000'000};
    return 0;
  }

  std::shared_ptr<State> state_;
  std::mutex mutex_;
  bool open_ = false;
  bool streaming_ = false;
  Mode mode_{};
  std::vector<std::vector<std::vector<std::uint8_t>>> buffers_;  // per buffer, per plane
  std::vector<std::vector<std::vector<std::uint8_t>>> retired_;
  std::deque<std::uint32_t> queue_;
};

}  // namespace surroundd::testing
